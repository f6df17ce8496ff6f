// ssx_rt_study: the paper's real-time study (section 3.2, Fig. 5).
//
// For each N, a scene of N quadrotors with the full stack per robot (quadrotor driver with motor
// model and both control loops, IMU, pose and range sensors, formation with obstacle avoidance)
// runs in real time at tau = 0.02 s and records the compute time of every step. The formation's
// radius grows with sqrt(N) so that the spacing stays about 1.5 m. Prints, last for each N:
//   n=1000 samples=5000 median_ms=1.23 p95_ms=1.50 p99_ms=1.80 max_ms=4.00 overruns=0 max_late_ms=0
//     late_steps=0 long_steps=0 began_late=0 physics_ms=0.3 sensors_ms=0.4 drivers_ms=0.5
//     other_ms=0.03 us_per_robot=1.23 heap_mib=17.1 kib_per_robot=17.5
// (overruns: samples with a late step; max_late_ms: the most any one step ended past its deadline;
// late_steps, long_steps, began_late: steps, as TimingSummary counts them (late; of those, longer
// than a step; of the others, begun late after an on-time step); phase medians per sample; other =
// snapshot and hooks (the neighbour index is rebuilt by the first range sensor to ask, in the
// sensors phase); us_per_robot = the median sample over N; heap_mib = the heap the scene and its
// started world hold (mallinfo2: the engine's and plugins' included); kib_per_robot = that over N)
//
// usage: ssx_rt_study [--n N]... [--samples K] [--threads T] [--physics-hz H] [--tau S] [--csv FILE]
//                     [--steps-csv FILE] [--physics ode|bullet] [--rt-priority P] [--fast]
//   --physics-hz  physics rate (default 1/tau: one physics step per tau, as the paper). When it is
//                 faster than 1/tau the environment steps at min(H, 500 Hz) with the rest as physics
//                 substeps, the inner loop runs at that step rate, and one sample is the compute
//                 time of the steps of one tau
//   --steps-csv   every step's timing (phases, lateness) of the last N, as `ssx run --stats-csv`
//   --fast        do not pace against the wall clock (for tests; overruns are then not measured)
//   --rt-priority step at SCHED_FIFO priority P (1-99; RunOptions::realtime_priority): needs root
//                 or CAP_SYS_NICE
#include <ssx/ssx.hpp>

#include <malloc.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace {

// bytes the C heap has handed out and not had back (mmapped blocks included)
std::size_t heapInUse() {
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;
}

struct Options {
  std::vector<int> sizes;
  int samples = 5000;
  int threads = 0;
  double tau = 0.02;
  double physics_hz = 0;  // 0: 1/tau
  std::string csv;
  std::string steps_csv;  // every step's timing, for the last N (TimingRecorder::writeCsv)
  bool fast = false;
  int rt_priority = 0;
  std::string physics;  // the engine, if not the scene's
};

// the scene for N robots: the environment steps at the physics rate when it is faster than 1/tau
std::string sceneFor(int n, const Options& o) {
  const double physics_hz = o.physics_hz > 0 ? o.physics_hz : 1.0 / o.tau;
  // plugins step at most at 500 Hz (the inner loop's rate); faster physics runs as substeps
  const double step = std::min(o.tau, std::max(1.0 / physics_hz, 1.0 / 500.0));
  const int substeps = std::max(1, static_cast<int>(std::lround(step * physics_hz)));
  const double inner_hz = std::min(500.0, 1.0 / step);
  const double radius = std::max(1.5, 4.0 * std::sqrt(n / 70.0));
  const double half = std::max(3.0, 1.6 * radius);
  char xml[2048];
  std::snprintf(
      xml, sizeof xml,
      "<scene><environment timestep=\"%.6f\" seed=\"5\" threads=\"%s\"/><physics substeps=\"%d\"/>"
      "<type name=\"q\" file=\"mk_quad_formation.xml\"/><ground/>"
      "<obstacle name=\"pillar\" xyz=\"%.3f 0 3\"><cylinder radius=\"0.25\" length=\"6\"/></obstacle>"
      "<swarm type=\"q\" count=\"%d\" name=\"quad{i}\" layout=\"random\" min=\"%.3f %.3f 0.05\" max=\"%.3f %.3f 0.05\" "
      "min_distance=\"1.0\"><driver formation_index=\"{i}\" formation_size=\"%d\" formation_radius=\"%.3f\" "
      "formation_center=\"0 0 %.3f\" inner_rate_hz=\"%.3f\" outer_rate_hz=\"%.3f\" offset=\"0 0 1.5\" "
      "start_time=\"2\"/><sensor index=\"0\" period=\"%d\"/><sensor index=\"1\" period=\"%d\"/>"
      "<sensor index=\"2\" period=\"%d\"/></swarm></scene>",
      step, o.threads > 0 ? std::to_string(o.threads).c_str() : "auto", substeps, half + 1.5, n, -half, -half, half,
      half, n, radius, radius + 1.5, inner_hz, std::min(50.0, 1.0 / step),
      // the IMU at the inner loop's rate, motion capture and the range sensor at the outer loop's
      std::max(1, static_cast<int>(std::lround(1.0 / (inner_hz * step)))),
      std::max(1, static_cast<int>(std::lround(0.02 / step))), std::max(1, static_cast<int>(std::lround(0.02 / step))));
  return xml;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    try {
      if (a == "--n")
        o.sizes.push_back(std::stoi(value()));
      else if (a == "--samples")
        o.samples = std::stoi(value());
      else if (a == "--threads")
        o.threads = std::stoi(value());
      else if (a == "--physics-hz")
        o.physics_hz = std::stod(value());
      else if (a == "--tau")
        o.tau = std::stod(value());
      else if (a == "--csv")
        o.csv = value();
      else if (a == "--steps-csv")
        o.steps_csv = value();
      else if (a == "--fast")
        o.fast = true;
      else if (a == "--rt-priority")
        o.rt_priority = std::stoi(value());
      else if (a == "--physics")
        o.physics = value();
      else
        throw std::runtime_error("unknown option " + a);
    } catch (const std::exception& e) {
      std::fprintf(stderr,
                   "ssx_rt_study: %s\nusage: ssx_rt_study [--n N]... [--samples K] [--threads T] "
                   "[--physics-hz H] [--tau S] [--csv FILE] [--steps-csv FILE] [--fast] [--physics ode|bullet] "
                   "[--rt-priority P]\n",
                   e.what());
      return 2;
    }
  }
  if (o.rt_priority != 0) {
    const std::string problem = ssx::realtimePriorityProblem(o.rt_priority);
    if (!problem.empty()) {
      std::fprintf(stderr, "ssx_rt_study: --rt-priority %d: %s\n", o.rt_priority, problem.c_str());
      return 2;
    }
  }
  if (o.sizes.empty()) o.sizes = {1, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100};
  std::ofstream csv;
  if (!o.csv.empty()) {
    csv.open(o.csv);
    csv << "n,step,total_ns,physics_ns,sensors_ns,drivers_ns,lateness_ns\n";
  }
  for (int n : o.sizes) {
    try {
      const std::size_t heap_before = heapInUse();
      ssx::SceneOptions options;
      if (!o.physics.empty()) options.physics_engine = o.physics;
      ssx::Scene scene = ssx::loadSceneFromString(sceneFor(n, o), "rt_study.xml",
                                                  ssx::installedDataDirectory() / "artifacts", options);
      ssx::Environment& env = *scene.environment;
      env.setLogSink([](ssx::LogLevel, std::string_view) {});  // overruns are counted, not printed
      ssx::RunOptions run;
      run.mode = o.fast ? ssx::RunOptions::Mode::Fast : ssx::RunOptions::Mode::RealTime;
      run.realtime_priority = o.rt_priority;
      // the step at the physics rate; a sample is the compute time of one tau of simulated time
      const int per_tau = std::max(1, static_cast<int>(std::lround(o.tau / ssx::toSeconds(env.timestep()))));
      run.steps = static_cast<std::int64_t>(o.samples) * per_tau;
      env.start();
      // what the scene and its world hold on the heap (the engine's and plugins' included)
      const std::size_t heap_after = heapInUse();
      const double heap_mib = static_cast<double>(heap_after - std::min(heap_after, heap_before)) / 1048576.0;
      const ssx::TimingSummary summary = env.run(run);
      if (!o.steps_csv.empty()) env.timing().writeCsv(o.steps_csv);
      // fold the steps of each tau into one sample
      const auto& steps = env.timing().samples();
      std::vector<double> totals, physics, sensors, drivers, other;
      std::int64_t overruns = 0;
      ssx::Nanoseconds max_late = 0;  // the most any one step ended past its deadline
      for (std::size_t k = 0; k + per_tau <= steps.size(); k += per_tau) {
        ssx::StepTiming sum;
        for (int j = 0; j < per_tau; ++j) {
          const auto& s = steps[k + j];
          sum.total += s.total;
          sum.physics += s.physics;
          sum.sensors += s.sensors;
          sum.drivers += s.drivers;
          sum.lateness = std::max(sum.lateness, s.lateness);
        }
        overruns += sum.lateness > 0 ? 1 : 0;
        max_late = std::max(max_late, sum.lateness);
        totals.push_back(static_cast<double>(sum.total) * 1e-6);
        physics.push_back(static_cast<double>(sum.physics) * 1e-6);
        sensors.push_back(static_cast<double>(sum.sensors) * 1e-6);
        drivers.push_back(static_cast<double>(sum.drivers) * 1e-6);
        other.push_back(static_cast<double>(sum.total - sum.physics - sum.sensors - sum.drivers) * 1e-6);
        if (csv)
          csv << n << ',' << k / per_tau << ',' << sum.total << ',' << sum.physics << ',' << sum.sensors << ','
              << sum.drivers << ',' << sum.lateness << '\n';
      }
      std::vector<double> sorted = totals;
      std::sort(sorted.begin(), sorted.end());
      auto pct = [&](double p) {
        const auto r = static_cast<std::size_t>(std::ceil(p / 100.0 * sorted.size()));
        return sorted[std::min(sorted.size() - 1, r == 0 ? 0 : r - 1)];
      };
      auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v.empty() ? 0.0 : v[(v.size() - 1) / 2];
      };
      // per robot and tau of simulated time, from the median step
      const double us_per_robot = pct(50) * 1e3 / n;
      std::printf(
          "n=%d samples=%zu median_ms=%.3f p95_ms=%.3f p99_ms=%.3f max_ms=%.3f overruns=%lld "
          "max_late_ms=%.3f late_steps=%lld long_steps=%lld began_late=%lld physics_ms=%.3f sensors_ms=%.3f "
          "drivers_ms=%.3f other_ms=%.3f us_per_robot=%.3f heap_mib=%.1f kib_per_robot=%.1f\n",
          n, sorted.size(), pct(50), pct(95), pct(99), sorted.back(), static_cast<long long>(overruns),
          static_cast<double>(max_late) * 1e-6, static_cast<long long>(summary.overruns),
          static_cast<long long>(summary.overruns_long), static_cast<long long>(summary.overruns_began_late),
          median(physics), median(sensors), median(drivers), median(other), us_per_robot, heap_mib,
          heap_mib * 1024.0 / n);
      std::fflush(stdout);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "ssx_rt_study: n=%d: %s\n", n, e.what());
      return 1;
    }
  }
  return 0;
}
