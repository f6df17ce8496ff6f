// The same scene and seed give bitwise identical states whatever the number of threads.
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <memory>
#include <thread>

using namespace ssx;

namespace {

struct NoisyPose : Measurement {
  Vec3 position = Vec3::Zero();
};

// ground-truth position plus Gaussian noise from the sensor's own stream
class NoisyPoseSensor final : public SensorOf<NoisyPose> {
 public:
  void sense(const StepInfo& info) override {
    output().stamp = info.time;
    output().position =
        artifact().pose().position + Vec3(random().normal(), random().normal(), random().normal()) * 0.01;
  }
};

// pushes towards the neighbour's noisy position it hears about, plus a random kick
class JitterDriver final : public Driver {
 public:
  void configure(const Descriptor&, PluginSetup& setup) override {
    const Environment& env = environment();
    const Artifact& next = env.artifact((artifact().index() % (env.artifactCount() - 1)) + 1);
    setup.subscribe<NoisyPose>(next.sensor(0), [this](const NoisyPose& p) { heard_ = p.position; });
  }
  void step(const StepInfo&) override {
    const Vec3 toward = heard_ - artifact().pose().position;
    Vec3 kick(random().normal(), random().normal(), random().uniform(0, 2));
    artifact().root().addForce(toward * 2.0 + kick * 3.0, Frame::World, Vec3(0.02, 0, 0), Frame::Local);
  }

 private:
  Vec3 heard_ = Vec3::Zero();
};

struct Result {
  std::uint64_t hash;
  std::size_t max_contacts;
};

Environment makePile(int threads, std::uint64_t seed, const std::string& engine = "ode") {
  EnvironmentSettings s;
  s.physics.engine = engine;
  s.threads = threads;
  s.seed = seed;
  s.timestep = toNanoseconds(0.002);
  return Environment(s);
}

void populate(Environment& env) {
  env.addGround();
  // 40 boxes in a tight column: they fall on each other and on the ground
  for (int i = 0; i < 40; ++i) {
    Artifact& a = env.addArtifact("box" + std::to_string(i), test::at(0.05 * (i % 3), 0.04 * (i % 2), 0.2 + 0.25 * i));
    a.addPhysicRoot(test::boxBody(Vec3(0.2, 0.2, 0.2), 0.5));
    a.addSensor(std::make_unique<NoisyPoseSensor>(), {}, 1 + i % 3);
    a.setDriver(std::make_unique<JitterDriver>(), {}, 1 + i % 2);
  }
}

Result run(int threads, std::uint64_t seed, int steps, const std::string& engine = "ode") {
  auto env = std::make_unique<Environment>(makePile(threads, seed, engine).settings());
  populate(*env);
  std::size_t max_contacts = 0;
  for (int i = 0; i < steps; ++i) {
    env->step();
    max_contacts = std::max(max_contacts, env->physics().contactCount());
  }
  return {env->stateHash(), max_contacts};
}

}  // namespace

TEST_CASE("1, 2 and 4 threads give bitwise identical states after 1000 steps with contacts, on either engine",
          "[determinism]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  const Result one = run(1, 7, 1000, engine);
  const Result two = run(2, 7, 1000, engine);
  const Result four = run(4, 7, 1000, engine);
  CHECK(one.max_contacts > 20);  // the pile really touches
  CHECK(one.hash == two.hash);
  CHECK(one.hash == four.hash);
  // and the seed matters
  CHECK(run(2, 8, 1000, engine).hash != one.hash);
}

TEST_CASE("two environments stepped in turn do not disturb each other", "[determinism]") {
  const std::uint64_t alone = run(1, 11, 300).hash;
  Environment a(makePile(1, 11).settings());
  Environment b(makePile(2, 99).settings());
  populate(a);
  populate(b);
  for (int i = 0; i < 300; ++i) {
    a.step();
    b.step();  // its QuickStep draws from ODE's global random seed too
  }
  CHECK(a.stateHash() == alone);
}

TEST_CASE("two environments with contacts stepped at the same time on two threads give their bits alone",
          "[determinism][parallel]") {
  // (each world's QuickStep draws its constraint order from its own seed, on its own thread)
  const std::uint64_t alone_a = run(1, 11, 300).hash;
  const std::uint64_t alone_b = run(1, 99, 300).hash;
  REQUIRE(alone_a != alone_b);
  Environment a(makePile(1, 11).settings());
  Environment b(makePile(1, 99).settings());
  populate(a);
  populate(b);
  std::thread other([&] { b.step(300); });
  a.step(300);
  other.join();
  CHECK(a.stateHash() == alone_a);
  CHECK(b.stateHash() == alone_b);
}
