// ssx_bench_import: what a robot from URDF or SDF costs (docs/robots.md).
//
// 1. For each robot of examples/robots: the time `ssx import` takes to read it (the description,
//    its meshes through assimp, the convex hulls of the moving links' meshes, the check that it
//    builds), cold, in a process of its own; then the time to load and start a scene holding one
//    of it, the memory that scene holds (glibc's mallinfo2, allocated bytes, given back when it
//    ends), that less what a scene of one box holds (the step timing ring, 16 MiB by default, is
//    in both), and what stayed allocated after it ended (the readers' and the mesh cache's):
//      robot=kuka_iiwa/model.urdf import_s=0.170 bodies=8 joints=7 ... scene_s=0.070 scene_kib=18709
//        beyond_one_box_kib=2200 kept_after_kib=11
// 2. An imported robot against the same robot in ssx's XML: 100 Crazyflies read from Bitcraze's
//    Gazebo model (a box, four propeller links on hinges, COLLADA meshes drawn only), 100 of the
//    artifact file `ssx import` prints for it, and 100 of ssx's own crazyflie.xml (a box, four
//    rotor points: one body, not five), all flown to 1 m by the quadrotor driver's Crazyflie preset
//    at 500 Hz, in turns (--rounds, default 3), one thread:
//      step round=0 n=100 threads=1 sdf_us_per_robot_step=8.0 printed_xml_us=8.0 ratio_sdf_to_printed=1.00 ...
// 3. Real time: the imported 100 on the default threads, every step timed against its 2 ms:
//      realtime n=100 median_ms=0.21 p99_ms=0.30 max_ms=0.9 late=0 of 5000 mean_height_m=1.00
// usage: ssx_bench_import [--rounds K] [--n N] [--steps S]
#include <ssx/ssx.hpp>

#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double allocatedBytes() { return static_cast<double>(mallinfo2().uordblks); }

const fs::path kRobots = fs::path(SSX_EXAMPLES_DIR) / "robots";
const char* const kCrazyflieSdf = "crazyflie/simulator_files/gazebo/crazyflie/model.sdf";

// a scene of one robot of this description at 1 m (a static-rooted arm stands where its file puts it)
fs::path writeOne(const fs::path& dir, const std::string& robot) {
  const fs::path scene = dir / "one.xml";
  std::ofstream(scene) << "<scene>\n  <environment timestep=\"0.002\" seed=\"1\"/>\n"
                       << "  <type name=\"r\" file=\"" << (kRobots / robot).string() << "\"/>\n  <ground/>\n"
                       << "  <artifact name=\"r\" type=\"r\" xyz=\"0 0 1\"/>\n</scene>\n";
  return scene;
}

// how a swarm's Crazyflie is described: read from the SDF model, from the artifact file `ssx import`
// prints for it, or ssx's own crazyflie.xml
enum class Source { Sdf, Printed, Own };

// n Crazyflies in a grid 0.5 m apart taking off to 1 m
fs::path writeSwarm(const fs::path& dir, Source source, int n) {
  const char* names[] = {"sdf.xml", "printed.xml", "own.xml"};
  const fs::path scene = dir / names[static_cast<int>(source)];
  std::ofstream out(scene);
  out << "<scene>\n  <environment timestep=\"0.002\" seed=\"1\"/>\n";
  if (source == Source::Own) {
    out << "  <type name=\"cf\" file=\"" << SSX_EXAMPLES_DIR << "/artifacts/crazyflie.xml\"/>\n";
  } else {
    fs::path file = kRobots / kCrazyflieSdf;
    if (source == Source::Printed) {
      file = dir / "crazyflie_printed.xml";
      std::ofstream(file) << ssx::importRobotDescription(kRobots / kCrazyflieSdf, dir).artifact_xml;
    }
    out << "  <type name=\"cf\" file=\"" << file.string() << "\">\n"
        << "    <driver plugin=\"quadrotor\" preset=\"crazyflie\" directions=\"-1 1 -1 1\"\n"
        << "            rotors=\"crazyflie/m1_prop crazyflie/m2_prop crazyflie/m3_prop crazyflie/m4_prop\"/>\n"
        << "    <sensor plugin=\"imu\"/>\n"
        << "    <sensor plugin=\"pose\" position_noise=\"0.0005\" velocity_noise=\"0.005\"/>\n  </type>\n";
  }
  out << "  <ground/>\n  <swarm type=\"cf\" count=\"" << n
      << "\" name=\"cf{i}\" layout=\"grid\" spacing=\"0.5\" xyz=\"0 0 0.05\">\n"
      << "    <driver offset=\"0 0 1\"/>\n  </swarm>\n</scene>\n";
  return scene;
}

double meanHeight(const ssx::Environment& env) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    const ssx::Artifact& a = env.artifact(i);
    if (a.rootCount() == 0 || a.root().isStatic()) continue;
    sum += a.root().pose().position.z();
    ++n;
  }
  return n ? sum / static_cast<double>(n) : 0;
}

// one description, in a child process so that its import is cold and its memory its own
bool importOne(const fs::path& dir, const std::string& robot) {
  std::fflush(stdout);
  const pid_t child = fork();
  if (child < 0) return false;
  if (child == 0) {
    const auto t0 = Clock::now();
    const ssx::ImportedRobot r = ssx::importRobotDescription(kRobots / robot);
    const double import_s = seconds(t0);
    const fs::path scene = writeOne(dir, robot);
    // what any scene costs this process once (plugins, the engines' first world, the worker pool),
    // taken first so that the robot's scene counts only what it holds; and what a scene of one box
    // holds (the step timing ring, 16 MiB by default, the worker pool, the ground), taken second
    const fs::path box = dir / "box.xml";
    std::ofstream(box) << "<scene><environment timestep=\"0.002\" seed=\"1\"/><ground/><type name=\"b\" file=\""
                       << SSX_EXAMPLES_DIR << "/artifacts/box.xml\"/><artifact name=\"b\" type=\"b\" xyz=\"3 3 0.5\"/></scene>\n";
    double box_held = 0;
    for (int k = 0; k < 2; ++k) {
      const double start = allocatedBytes();
      ssx::Scene e = ssx::loadScene(box);
      e.environment->start();
      e.environment->step(10);
      box_held = allocatedBytes() - start;
    }
    const double before = allocatedBytes();
    const auto t1 = Clock::now();
    double scene_s = 0, held = 0;
    {
      ssx::Scene s = ssx::loadScene(scene, ssx::SceneOptions{});
      s.environment->start();
      scene_s = seconds(t1);
      s.environment->step(10);
      held = allocatedBytes();
    }
    // what the scene held is what its end gave back; what stayed is the process's (caches of the
    // libraries that read the description, the mesh cache)
    const double after = allocatedBytes();
    std::printf("robot=%s import_s=%.3f bodies=%zu joints=%zu mass_kg=%.3f warnings=%zu scene_s=%.3f scene_kib=%.0f "
                "beyond_one_box_kib=%.0f kept_after_kib=%.0f\n",
                robot.c_str(), import_s, r.bodies, r.joints, r.mass, r.warnings.size(), scene_s, (held - after) / 1024,
                (held - after - box_held) / 1024, (after - before) / 1024);
    std::fflush(stdout);
    _exit(0);
  }
  int status = 0;
  return waitpid(child, &status, 0) == child && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// us per robot step of `steps` steps after 250 to take off
double stepCost(const fs::path& scene, int n, int steps, double& height) {
  ssx::SceneOptions options;
  options.threads = 1;
  ssx::Scene s = ssx::loadScene(scene, options);
  s.environment->start();
  s.environment->step(250);
  const auto t0 = Clock::now();
  s.environment->step(steps);
  const double us = seconds(t0) * 1e6 / (static_cast<double>(steps) * n);
  height = meanHeight(*s.environment);
  return us;
}

}  // namespace

int main(int argc, char** argv) {
  int rounds = 3, n = 100, steps = 2500;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--rounds") == 0 && i + 1 < argc) {
      rounds = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--n") == 0 && i + 1 < argc) {
      n = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--steps") == 0 && i + 1 < argc) {
      steps = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: ssx_bench_import [--rounds K] [--n N] [--steps S]\n");
      return 2;
    }
  }
  if (rounds < 1 || n < 1 || steps < 1) {
    std::fprintf(stderr, "ssx_bench_import: --rounds, --n and --steps must be positive\n");
    return 2;
  }
  char pattern[] = "/tmp/ssx_bench_import_XXXXXX";
  const fs::path dir = mkdtemp(pattern);
  for (const char* robot : {"kuka_iiwa/model.urdf", "kuka_iiwa/model.sdf", "husky/husky.urdf", kCrazyflieSdf,
                            "quadrotor/quadrotor.urdf", "simple/cartpole.urdf", "simple/door.urdf"}) {
    if (!importOne(dir, robot)) {
      std::fprintf(stderr, "ssx_bench_import: %s failed\n", robot);
      return 1;
    }
  }

  const fs::path imported = writeSwarm(dir, Source::Sdf, n), printed = writeSwarm(dir, Source::Printed, n),
                 own = writeSwarm(dir, Source::Own, n);
  for (int round = 0; round < rounds; ++round) {
    double h_imported = 0, h_printed = 0, h_own = 0;
    const double a = stepCost(imported, n, steps, h_imported);
    const double b = stepCost(printed, n, steps, h_printed);
    const double c = stepCost(own, n, steps, h_own);
    std::printf("step round=%d n=%d threads=1 sdf_us_per_robot_step=%.3f printed_xml_us=%.3f ratio_sdf_to_printed=%.2f "
                "own_crazyflie_xml_us=%.3f ratio_sdf_to_own=%.2f mean_height_m=%.3f/%.3f/%.3f\n",
                round, n, a, b, a / b, c, a / c, h_imported, h_printed, h_own);
    std::fflush(stdout);
  }

  // real time: each step of the imported swarm, on the default threads, against its timestep
  ssx::Scene s = ssx::loadScene(imported, ssx::SceneOptions{});
  s.environment->start();
  const double budget_ms = static_cast<double>(s.environment->timestep()) * 1e-6;
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(steps));
  for (int i = 0; i < steps; ++i) {
    const auto t0 = Clock::now();
    s.environment->step();
    ms.push_back(seconds(t0) * 1e3);
  }
  const long late = std::count_if(ms.begin(), ms.end(), [&](double t) { return t > budget_ms; });
  std::sort(ms.begin(), ms.end());
  std::printf("realtime n=%d threads=default budget_ms=%.1f median_ms=%.3f p99_ms=%.3f max_ms=%.3f late=%ld of %d "
              "mean_height_m=%.3f\n",
              n, budget_ms, ms[ms.size() / 2], ms[ms.size() * 99 / 100], ms.back(), late, steps,
              meanHeight(*s.environment));
  fs::remove_all(dir);
  return 0;
}
