// After warm-up a step allocates nothing, a learning batch's step neither: counted by replacing
// the global operator new of this test program. (ODE allocates with malloc inside its own pools;
// what is counted here is every C++ allocation: the core, the plugins, the worker pool, timing,
// callbacks.)
#include <ssx/ssx.hpp>
#include <ssx/vector_environment.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <string>
#include <vector>

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};

void* allocate(std::size_t size, std::size_t alignment) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (size == 0) size = 1;
  void* p = alignment > alignof(std::max_align_t) ? std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment)
                                                  : std::malloc(size);
  return p;
}
}  // namespace

// (GCC sees free() on memory from operator new and warns; here operator new is malloc)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

void* operator new(std::size_t size) {
  if (void* p = allocate(size, 0)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return allocate(size, 0); }
void* operator new(std::size_t size, std::align_val_t a) {
  if (void* p = allocate(size, static_cast<std::size_t>(a))) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  return allocate(size, static_cast<std::size_t>(a));
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

using namespace ssx;
namespace fs = std::filesystem;

TEST_CASE("after warm-up a step allocates nothing: quadrotors, formation, contacts, 2 threads, either engine",
          "[allocation]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  const fs::path artifacts = fs::path(SSX_EXAMPLES_DIR) / "artifacts";
  const std::string xml =
      "<scene><environment timestep=\"0.002\" seed=\"3\" threads=\"2\"/><physics engine=\"" + engine + "\"/>"
      "<type name=\"quad\" file=\"" + (artifacts / "mk_quad_formation.xml").string() +
      "\"/><type name=\"box\" file=\"" + (artifacts / "box.xml").string() + "\"/><ground/>"
      "<obstacle name=\"pillar\" xyz=\"2.5 0 2\"><cylinder radius=\"0.25\" length=\"4\"/></obstacle>"
      "<swarm type=\"quad\" count=\"12\" layout=\"random\" min=\"-2 -2 0.05\" max=\"2 2 0.05\" min_distance=\"1.0\">"
      "<driver formation_index=\"{i}\" formation_size=\"12\" formation_radius=\"1.5\" formation_center=\"0 0 2.5\" "
      "offset=\"0 0 1\" start_time=\"0.3\"/></swarm>"
      "<swarm type=\"box\" name=\"box{i}\" count=\"12\" layout=\"random\" min=\"4 -0.3 0.2\" max=\"4.6 0.3 2.5\" "
      "min_distance=\"0.3\"/></scene>";
  Scene scene = loadSceneFromString(xml, "alloc.xml", artifacts);
  Environment& env = *scene.environment;
  // the allocator is really replaced: a vector counts
  g_counting = true;
  { std::vector<int> probe(3); }
  g_counting = false;
  REQUIRE(g_allocations.load() == 1);
  g_allocations = 0;

  env.step(500);  // warm-up: take-off, the formation forming, boxes landing
  g_counting = true;
  env.step(1500);  // 3 s more: formation flight, contacts, range sensing
  g_counting = false;
  CHECK(g_allocations.load() == 0);
  CHECK(env.timing().size() == 2000);
}

TEST_CASE("after warm-up a learning step allocates nothing: commands, steps and readings of copies on 2 threads",
          "[allocation][learn]") {
  // ssx.learn's batch step: every copy takes its robots' commands (attitude, or each rotor's
  // speed), steps 10 times and writes its states and IMU readings, on the worker pool (a copy left
  // out, as a batch whose copies are being reset leaves them)
  const bool rotors = GENERATE(false, true);
  INFO((rotors ? "rotor speeds" : "attitude"));
  const fs::path artifacts = fs::path(SSX_EXAMPLES_DIR) / "artifacts";
  auto load = [&artifacts](std::size_t i) {
    SceneOptions options;
    options.threads = 1;
    return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"" + std::to_string(5 + i) +
                                   "\"/><type name=\"cf\" file=\"" + (artifacts / "crazyflie.xml").string() +
                                   "\"/><ground/><swarm type=\"cf\" count=\"2\" spacing=\"1\" xyz=\"0 0 0.05\">"
                                   "<driver offset=\"0 0 1\"/></swarm></scene>",
                               "cf.xml", artifacts, options);
  };
  const std::size_t copies = 6, robots = 2;
  VectorEnvironment v(load, copies, 2);
  std::vector<double> commands(copies * robots * 4), states(copies * robots * kRobotStateSize),
      imu(copies * robots * 6);
  for (std::size_t k = 0; k < commands.size(); k += 4)  // level, about the weight
    if (rotors)
      std::fill_n(commands.begin() + static_cast<std::ptrdiff_t>(k), 4, 1770.0);  // rad/s
    else
      commands[k + 3] = 0.3;  // N
  std::vector<std::uint8_t> active(copies, 1);
  active[2] = 0;
  const VectorEnvironment::StepIO io{rotors ? CommandLevel::Rotors : CommandLevel::Attitude, commands, 4, states, imu};
  v.step(400);  // warm-up: take-off
  for (int batch = 0; batch < 3; ++batch) v.step(10, active, io);
  const double z = states[2];
  g_allocations = 0;
  g_counting = true;
  for (int batch = 0; batch < 20; ++batch) v.step(10, active, io);
  g_counting = false;
  CHECK(g_allocations.load() == 0);
  CHECK(states[2] != z);  // (the steps were taken and read)
}
