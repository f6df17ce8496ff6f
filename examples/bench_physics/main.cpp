// ssx_bench_physics: cost per body and step of each physics engine (ODE, Bullet).
//
// Two worlds of N bodies (boxes of 0.2 m, 1 kg), stepped at 1 kHz on 1 and 2 threads:
//   free      - bodies falling in a 3D grid 2 m apart: no contacts, integration only;
//   contacts  - columns of two boxes standing on the ground 0.5 m apart: every body in contact
//               (with the ground or the box below it), three to four points per contact.
// Prints the median of the physics phase per body and step (us) and the contact points per step.
//
// usage: ssx_bench_physics [--quick]
#include <ssx/ssx.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

struct Result {
  double us_per_body;
  double contacts_per_step;
};

Result measure(const std::string& engine, bool contacts, int n, int threads, int steps) {
  ssx::EnvironmentSettings s;
  s.threads = threads;
  s.timestep = ssx::toNanoseconds(0.001);
  s.physics.engine = engine;
  ssx::Environment env(s);
  ssx::PhysicNodeSpec box;
  box.name = "box";
  box.shapes.push_back(ssx::Shape::box(ssx::Vec3(0.2, 0.2, 0.2)));
  box.mass = 1.0;
  if (contacts) {
    env.addGround();
    const int columns = n / 2;
    const int side = static_cast<int>(std::ceil(std::sqrt(columns)));
    for (int i = 0; i < n; ++i) {
      const int c = i / 2;
      const ssx::Vec3 p(0.5 * (c % side), 0.5 * (c / side), 0.1 + 0.2 * (i % 2));
      env.addArtifact("b" + std::to_string(i), {p, ssx::Quat::Identity()}).addPhysicRoot(box);
    }
  } else {
    const int side = static_cast<int>(std::ceil(std::cbrt(n)));
    for (int i = 0; i < n; ++i) {
      const ssx::Vec3 p(2.0 * (i % side), 2.0 * ((i / side) % side), 2.0 * (i / (side * side)));
      env.addArtifact("b" + std::to_string(i), {p, ssx::Quat::Identity()}).addPhysicRoot(box);
    }
  }
  env.step(50);  // settled, pool threads and caches warm
  env.timing().clear();
  double points = 0;
  for (int k = 0; k < steps; ++k) {
    env.step();
    points += static_cast<double>(env.physics().contactCount());
  }
  std::vector<ssx::Nanoseconds> v;
  for (const auto& t : env.timing().samples()) v.push_back(t.physics);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return {static_cast<double>(v[v.size() / 2]) * 1e-3 / n, points / steps};
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const std::vector<int> sizes = quick ? std::vector<int>{100, 1000} : std::vector<int>{100, 1000, 10000};
  std::printf("# physics phase per body and step (us, median), 1 kHz, boxes of 0.2 m\n");
  std::printf("%-7s %-9s %6s %7s %11s %9s\n", "engine", "world", "N", "threads", "us_per_body", "contacts");
  for (const std::string& engine : ssx::physicEngineNames())
    for (const bool contacts : {false, true})
      for (const int n : sizes)
        for (const int threads : {1, 2}) {
          const int steps = std::clamp(1'000'000 / n, 50, 2000) / (quick ? 4 : 1);
          const Result r = measure(engine, contacts, n, threads, steps);
          std::printf("%-7s %-9s %6d %7d %11.4f %9.0f\n", engine.c_str(), contacts ? "contacts" : "free", n, threads,
                      r.us_per_body, r.contacts_per_step);
          std::fflush(stdout);
        }
  return 0;
}
