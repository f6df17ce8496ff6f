// ssx_bench_ground: the cost of ground swarms, beside the figures ARGoS gave on this machine.
//
// The diffusion scene (examples/ground/diffusion.xml's e-pucks, swarm model, eight proximity rays
// and a range-and-bearing board each; 50 control steps and 500 physics steps per simulated second)
// with N = 100, 1,000 and 10,000 e-pucks packed as there (0.2 m apart) in an arena with room to
// spread, on 1 and 2 threads, as fast as the machine goes: the median and 95th percentile of the
// time per 20 ms tick, and per robot. Then the full model (each e-puck five bodies: wheels on hinge
// motors, casters) on ODE and Bullet: the cost per robot and physics step. Then TurtleBot3 Burgers
// (full model: four bodies, the chassis four times as long as a wheel), standing in rows 1 m apart,
// on ODE, 1 and 2 threads: the physics phase per robot and step, 100 to 10,000 robots.
//
// usage: ssx_bench_ground [--quick] [--ticks T]
#include <ssx/ssx.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

const std::string kArtifacts = std::string(SSX_EXAMPLES_DIR) + "/artifacts";

std::string arena(double half) {
  char walls[1024];
  const double len = 2 * half + 0.2;
  std::snprintf(walls, sizeof walls,
                R"(<obstacle name="north" xyz="0 %.3f 0.05"><box size="%.3f 0.1 0.1"/></obstacle>
  <obstacle name="south" xyz="0 %.3f 0.05"><box size="%.3f 0.1 0.1"/></obstacle>
  <obstacle name="east" xyz="%.3f 0 0.05"><box size="0.1 %.3f 0.1"/></obstacle>
  <obstacle name="west" xyz="%.3f 0 0.05"><box size="0.1 %.3f 0.1"/></obstacle>)",
                half + 0.05, len, -half - 0.05, len, half + 0.05, len, -half - 0.05, len);
  return walls;
}

struct Timing {
  double median_ms, p95_ms;
  double physics_median_ms;  // the physics phase's median
};

Timing run(const std::string& xml, int ticks, int warmup, double* physics_share = nullptr) {
  ssx::SceneOptions options;
  ssx::Scene scene = ssx::loadSceneFromString(xml, "bench_ground.xml", kArtifacts, options);
  ssx::Environment& env = *scene.environment;
  env.step(warmup);
  std::vector<double> ms, physics_ms;
  double physics = 0, total = 0;
  for (int i = 0; i < ticks; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    env.step();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    const auto& last = env.timing()[env.timing().size() - 1];
    physics += static_cast<double>(last.physics);
    total += static_cast<double>(last.total);
    physics_ms.push_back(1e-6 * static_cast<double>(last.physics));
  }
  std::sort(ms.begin(), ms.end());
  std::sort(physics_ms.begin(), physics_ms.end());
  if (physics_share != nullptr) *physics_share = total > 0 ? physics / total : 0;
  return {ms[ms.size() / 2], ms[std::min(ms.size() - 1, ms.size() * 95 / 100)], physics_ms[physics_ms.size() / 2]};
}

std::string swarmScene(int n, int threads) {
  const int columns = static_cast<int>(std::ceil(std::sqrt(n)));
  const double packed = 0.2 * (columns - 1);
  const double half = std::max(2.0, 0.8 * packed);  // the arena: room to spread
  return R"(<scene><environment timestep="0.02" seed="11" threads=")" + std::to_string(threads) +
         R"("/><physics substeps="10"/><type name="epuck" file="epuck.xml"/><ground/>)" + arena(half) +
         R"(<swarm type="epuck" count=")" + std::to_string(n) + R"(" name="e{i}" layout="grid" spacing="0.2" random_yaw="true" xyz=")" +
         std::to_string(-packed / 2) + " " + std::to_string(-packed / 2) +
         R"( 0"><driver controller="diffusion"/></swarm></scene>)";
}

std::string fullScene(int n, const std::string& engine) {
  const int columns = static_cast<int>(std::ceil(std::sqrt(n)));
  const double packed = 0.2 * (columns - 1);
  return R"(<scene><environment timestep="0.002" seed="11" threads="2"/><physics engine=")" + engine +
         R"("/><type name="epuck" file="epuck_full.xml"/><ground/><swarm type="epuck" count=")" + std::to_string(n) +
         R"(" name="e{i}" layout="grid" spacing="0.2" random_yaw="true" xyz=")" + std::to_string(-packed / 2) + " " +
         std::to_string(-packed / 2) + R"( 0"><driver controller="diffusion"/></swarm></scene>)";
}

std::string burgerScene(int n, int threads) {
  return R"(<scene><environment timestep="0.002" seed="11" threads=")" + std::to_string(threads) +
         R"("/><type name="burger" file="turtlebot3_burger.xml"/><ground/><swarm type="burger" count=")" +
         std::to_string(n) + R"(" name="b{i}" spacing="1"/></scene>)";
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int ticks = 150;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) quick = true;
    else if (std::strcmp(argv[i], "--ticks") == 0 && i + 1 < argc) ticks = std::atoi(argv[++i]);
  }
  if (quick) ticks = 20;
  std::printf("swarm model: e-pucks, 8 proximity rays + range-and-bearing each, 20 ms ticks of 10 physics steps\n");
  std::printf("ARGoS on this machine: 1,000 foot-bots 22.9 ms/tick on 1 thread, 17.2 on 2, 11.4 best;"
              " 10,000: 365, 265, 201\n\n");
  std::printf("%8s %8s %12s %10s %14s %10s\n", "robots", "threads", "median ms", "p95 ms", "us per robot", "physics");
  const std::vector<int> counts = quick ? std::vector<int>{100, 1000} : std::vector<int>{100, 1000, 10000};
  for (const int n : counts) {
    for (const int threads : {1, 2}) {
      double share = 0;
      const int t = n >= 10000 ? std::max(10, ticks / 5) : ticks;
      const Timing timing = run(swarmScene(n, threads), t, 10, &share);
      std::printf("%8d %8d %12.2f %10.2f %14.2f %9.0f%%\n", n, threads, timing.median_ms, timing.p95_ms,
                  1000.0 * timing.median_ms / n, 100 * share);
      std::fflush(stdout);
    }
  }
  std::printf("\nfull model: e-pucks of 5 bodies (hinge-motor wheels, ball casters), 2 ms steps, 2 threads\n");
  std::printf("%8s %8s %12s %20s\n", "robots", "engine", "median ms", "us per robot-step");
  for (const char* engine : {"ode", "bullet"}) {
    for (const int n : quick ? std::vector<int>{100} : std::vector<int>{100, 1000}) {
      const Timing timing = run(fullScene(n, engine), ticks, 50);
      std::printf("%8d %8s %12.3f %20.2f\n", n, engine, timing.median_ms, 1000.0 * timing.median_ms / n);
      std::fflush(stdout);
    }
  }
  std::printf("\nTurtleBot3 Burgers, full model (4 bodies), standing 1 m apart, 2 ms steps, ODE: physics phase\n");
  std::printf("%8s %8s %12s %20s\n", "robots", "threads", "median ms", "us per robot-step");
  for (const int n : quick ? std::vector<int>{100} : std::vector<int>{100, 1000, 10000}) {
    for (const int threads : {1, 2}) {
      const double ms = run(burgerScene(n, threads), n >= 10000 ? std::max(10, ticks / 5) : ticks, 5).physics_median_ms;
      std::printf("%8d %8d %12.3f %20.2f\n", n, threads, ms, 1000.0 * ms / n);
      std::fflush(stdout);
    }
  }
  return 0;
}
