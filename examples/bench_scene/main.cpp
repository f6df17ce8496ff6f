// ssx_bench_scene: how long a scene with a large swarm takes to load (parse, resolve, load plugins,
// create every artifact and plugin instance) and to start (engines and configure).
//
// Writes a scene with one swarm of N artifacts of a quadrotor-sized body with a pose sensor, a
// clock sensor and the hover driver, for N = 1,000, 10,000 and 30,000, and prints the best of three
// loads. usage: ssx_bench_scene [--quick]
#include <ssx/ssx.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

namespace fs = std::filesystem;

namespace {

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

fs::path writeScene(const fs::path& dir, int n) {
  std::ofstream(dir / "robot.xml") << R"(<artifact>
  <physic name="body" mass="0.82" inertia="0.009 0.009 0.018">
    <box size="0.2 0.2 0.06"/>
    <physic name="arm"><cylinder radius="0.01" length="0.45" rpy="0 1.5707963 0" density="500"/></physic>
  </physic>
  <render follow="body"><box size="0.2 0.2 0.06" color="0.2 0.3 0.8"/></render>
  <sensor plugin="pose" position_noise="0.002"/>
  <sensor plugin="clock" period="50"/>
  <driver plugin="hover" offset="0 0 1"/>
</artifact>
)";
  const fs::path scene = dir / ("swarm_" + std::to_string(n) + ".xml");
  std::ofstream(scene) << "<scene>\n  <environment timestep=\"0.02\" seed=\"1\"/>\n"
                       << "  <type name=\"robot\" file=\"robot.xml\"/>\n  <ground/>\n"
                       << "  <swarm type=\"robot\" count=\"" << n
                       << "\" name=\"quad{i}\" layout=\"grid\" spacing=\"1.5\"/>\n"
                       << "</scene>\n";
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  char pattern[] = "/tmp/ssx_bench_scene_XXXXXX";
  const fs::path dir = mkdtemp(pattern);
  std::printf("%8s %10s %10s %14s\n", "N", "load_s", "start_s", "load_us/robot");
  for (int n : quick ? std::vector<int>{1000} : std::vector<int>{1000, 10000, 30000}) {
    const fs::path scene = writeScene(dir, n);
    double best_load = 1e9, best_start = 1e9;
    for (int round = 0; round < 3; ++round) {
      auto t0 = std::chrono::steady_clock::now();
      ssx::Scene s = ssx::loadScene(scene);
      best_load = std::min(best_load, seconds(t0));
      t0 = std::chrono::steady_clock::now();
      s.environment->start();
      best_start = std::min(best_start, seconds(t0));
      if (s.environment->artifactCount() != static_cast<std::size_t>(n) + 1) return 1;
    }
    std::printf("%8d %10.3f %10.3f %14.2f\n", n, best_load, best_start, best_load / n * 1e6);
  }
  fs::remove_all(dir);
  return 0;
}
