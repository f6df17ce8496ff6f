// ssx_bench_scene: how long a scene with a large swarm takes to load (parse, resolve, load plugins,
// create every artifact and plugin instance) and to start (engines and configure), and how much
// memory each robot takes.
//
// Two robots: `light`, a quadrotor-sized body with a pose sensor, a clock sensor and the hover
// driver; and `full`, the formation study's mk_quad (rotor model, both control loops, IMU, pose
// and range sensors, formation driver), as ssx_rt_study flies it. For N = 1,000, 10,000 and
// 100,000 (30,000 for `light` too) it prints the best of three loads and starts (one for 100,000),
// and the resident memory the started environment adds per robot (measured on the first round,
// from /proc/self/statm, so it includes the allocator's overhead):
//   robot=full n=100000 load_s=1.20 start_s=0.80 total_s=2.00 load_us_per_robot=12.0 kib_per_robot=9.5
// usage: ssx_bench_scene [--quick] [--robot light|full] [--n N]...   (--robot and --n pick cases)
#include <ssx/ssx.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// resident memory of this process, bytes
double residentBytes() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE));
}

fs::path writeLight(const fs::path& dir, int n) {
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
  const fs::path scene = dir / ("light_" + std::to_string(n) + ".xml");
  std::ofstream(scene) << "<scene>\n  <environment timestep=\"0.02\" seed=\"1\"/>\n"
                       << "  <type name=\"robot\" file=\"robot.xml\"/>\n  <ground/>\n"
                       << "  <swarm type=\"robot\" count=\"" << n
                       << "\" name=\"quad{i}\" layout=\"grid\" spacing=\"1.5\"/>\n"
                       << "</scene>\n";
  return scene;
}

// the formation study's scene (as ssx_rt_study writes it, without the obstacle)
fs::path writeFull(const fs::path& dir, int n) {
  const double radius = std::max(1.5, 4.0 * std::sqrt(n / 70.0));
  const fs::path scene = dir / ("full_" + std::to_string(n) + ".xml");
  std::ofstream(scene) << "<scene>\n  <environment timestep=\"0.02\" seed=\"1\"/>\n"
                       << "  <type name=\"q\" file=\"" << SSX_EXAMPLES_DIR << "/artifacts/mk_quad_formation.xml\"/>\n"
                       << "  <ground/>\n"
                       << "  <swarm type=\"q\" count=\"" << n << "\" name=\"quad{i}\" layout=\"grid\" spacing=\"1.5\">\n"
                       << "    <driver formation_index=\"{i}\" formation_size=\"" << n << "\" formation_radius=\""
                       << radius << "\" offset=\"0 0 1.5\" inner_rate_hz=\"50\" outer_rate_hz=\"50\"/>\n"
                       << "    <sensor index=\"2\" period=\"1\"/>\n"
                       << "  </swarm>\n</scene>\n";
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string only_robot;
  std::vector<int> only_sizes;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[i], "--robot") == 0 && i + 1 < argc) {
      only_robot = argv[++i];
    } else if (std::strcmp(argv[i], "--n") == 0 && i + 1 < argc) {
      only_sizes.push_back(std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: ssx_bench_scene [--quick] [--robot light|full] [--n N]...\n");
      return 2;
    }
  }
  char pattern[] = "/tmp/ssx_bench_scene_XXXXXX";
  const fs::path dir = mkdtemp(pattern);
  struct Case {
    const char* robot;
    fs::path (*write)(const fs::path&, int);
    std::vector<int> sizes;
  };
  const std::vector<Case> cases = quick ? std::vector<Case>{{"light", writeLight, {1000}}, {"full", writeFull, {1000}}}
                                        : std::vector<Case>{{"light", writeLight, {1000, 10000, 30000, 100000}},
                                                            {"full", writeFull, {1000, 10000, 100000}}};
  for (const Case& c : cases) {
    if (!only_robot.empty() && only_robot != c.robot) continue;
    for (int n : only_sizes.empty() ? c.sizes : only_sizes) {
      const fs::path scene = c.write(dir, n);
      // each size in a process of its own, so that the memory it reports is its own
      std::fflush(stdout);
      const pid_t child = fork();
      if (child < 0) return 1;
      if (child == 0) {
        double best_load = 1e9, best_start = 1e9, best_total = 1e9, per_robot = 0;
        for (int round = 0; round < (n >= 100000 ? 1 : 3); ++round) {
          const double before = residentBytes();
          auto t0 = std::chrono::steady_clock::now();
          ssx::Scene s = ssx::loadScene(scene);
          const double load = seconds(t0);
          auto t1 = std::chrono::steady_clock::now();
          s.environment->start();
          const double start = seconds(t1);
          if (round == 0) per_robot = (residentBytes() - before) / n;
          best_load = std::min(best_load, load);
          best_start = std::min(best_start, start);
          best_total = std::min(best_total, load + start);
          if (s.environment->artifactCount() != static_cast<std::size_t>(n) + 1) _exit(1);
        }
        std::printf("robot=%s n=%d load_s=%.3f start_s=%.3f total_s=%.3f load_us_per_robot=%.2f kib_per_robot=%.1f\n",
                    c.robot, n, best_load, best_start, best_total, best_load / n * 1e6, per_robot / 1024);
        std::fflush(stdout);
        _exit(0);
      }
      int status = 0;
      if (waitpid(child, &status, 0) != child || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::fprintf(stderr, "ssx_bench_scene: robot=%s n=%d failed\n", c.robot, n);
        return 1;
      }
    }
  }
  fs::remove_all(dir);
  return 0;
}
