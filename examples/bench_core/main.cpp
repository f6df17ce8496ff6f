// ssx_bench_core: cost of the framework per artifact per step, by phase.
//
// Steps N free bodies (no gravity, no contacts), each with a trivial driver (reads its state,
// applies a force) and a trivial sensor (copies its pose), for N = 10 .. 10,000 on 1 and 2 threads,
// and prints the cost per artifact per step of each phase. "framework" is everything but ODE's own
// step (the trivial plugins' code is a few nanoseconds). A second table gives each driver about
// 2 us of work and reports the speed-up of the parallel phases on 2 threads.
//
// usage: ssx_bench_core [--quick]
#include <ssx/ssx.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

struct PoseMeasurement : ssx::Measurement {
  ssx::Vec3 position = ssx::Vec3::Zero();
};

class TrivialSensor final : public ssx::SensorOf<PoseMeasurement> {
 public:
  void sense(const ssx::StepInfo& info) override {
    output().stamp = info.time;
    output().position = artifact().root().pose().position;
  }
};

// a small deterministic workload: `iterations` rounds of a logistic map
double work(int iterations, double x) {
  for (int i = 0; i < iterations; ++i) x = 3.9 * x * (1.0 - x);
  return x;
}

class TrivialDriver final : public ssx::Driver {
 public:
  explicit TrivialDriver(int work_iterations) : iterations_(work_iterations) {}
  void step(const ssx::StepInfo&) override {
    ssx::PhysicNode& body = artifact().root();
    const ssx::Vec3 v = body.state().linear_velocity;
    x_ = work(iterations_, x_);
    body.addForce(-0.1 * v + ssx::Vec3(0, 0, 1e-9 * x_));
  }

 private:
  int iterations_;
  double x_ = 0.3;
};

struct Result {
  double physics_us, snapshot_us, sensors_us, drivers_us, total_us;  // per artifact per step
};

Result measure(int n, int threads, int work_iterations, int steps) {
  ssx::EnvironmentSettings s;
  s.threads = threads;
  s.timestep = ssx::toNanoseconds(0.001);
  s.physics.gravity = ssx::Vec3::Zero();
  ssx::Environment env(s);
  const int side = static_cast<int>(std::ceil(std::cbrt(n)));
  for (int i = 0; i < n; ++i) {
    ssx::PhysicNodeSpec body;
    body.name = "body";
    body.shapes.push_back(ssx::Shape::sphere(0.1));
    body.mass = 1.0;
    const ssx::Vec3 p(2.0 * (i % side), 2.0 * ((i / side) % side), 2.0 * (i / (side * side)));
    ssx::Artifact& a = env.addArtifact("r" + std::to_string(i), {p, ssx::Quat::Identity()});
    a.addPhysicRoot(body);
    a.addSensor(std::make_unique<TrivialSensor>());
    a.setDriver(std::make_unique<TrivialDriver>(work_iterations));
  }
  env.step(20);  // warm up: pool threads, caches
  env.timing().clear();
  env.step(steps);
  // medians per phase are robust to the odd preemption on a shared machine
  auto median = [&](auto field) {
    std::vector<ssx::Nanoseconds> v;
    for (const auto& t : env.timing().samples()) v.push_back(t.*field);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return static_cast<double>(v[v.size() / 2]) * 1e-3 / n;
  };
  return {median(&ssx::StepTiming::physics), median(&ssx::StepTiming::snapshot), median(&ssx::StepTiming::sensors),
          median(&ssx::StepTiming::drivers), median(&ssx::StepTiming::total)};
}

// iterations of the workload that take about `us` microseconds on this machine
int calibrate(double us) {
  int iterations = 1000;
  for (;;) {
    const auto t0 = std::chrono::steady_clock::now();
    volatile double sink = work(iterations, 0.3);
    (void)sink;
    const double took = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    if (took > 2000) return static_cast<int>(iterations * us / took);
    iterations *= 2;
  }
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const std::vector<int> sizes = quick ? std::vector<int>{10, 1000} : std::vector<int>{10, 100, 1000, 10000};

  std::printf("# framework cost per artifact per step, trivial driver + sensor, no contacts (us)\n");
  std::printf("%6s %7s %9s %9s %9s %9s %9s %10s\n", "N", "threads", "physics", "snapshot", "sensors", "drivers",
              "total", "framework");
  for (int n : sizes) {
    for (int threads : {1, 2}) {
      const int steps = std::clamp(2'000'000 / n, 100, 5000);
      const Result r = measure(n, threads, 0, quick ? steps / 4 : steps);
      std::printf("%6d %7d %9.4f %9.4f %9.4f %9.4f %9.4f %10.4f\n", n, threads, r.physics_us, r.snapshot_us,
                  r.sensors_us, r.drivers_us, r.total_us, r.total_us - r.physics_us);
    }
  }

  const int iterations = calibrate(2.0);
  std::printf("\n# drivers with ~2 us of work each (%d workload iterations): parallel phases (sensors + drivers)\n",
              iterations);
  std::printf("%6s %12s %12s %8s\n", "N", "1 thread us", "2 threads us", "speedup");
  for (int n : sizes) {
    if (n < 100) continue;
    const int steps = std::clamp(200'000 / n, 20, 1000);
    const Result one = measure(n, 1, iterations, quick ? steps / 4 : steps);
    const Result two = measure(n, 2, iterations, quick ? steps / 4 : steps);
    const double p1 = one.sensors_us + one.drivers_us;
    const double p2 = two.sensors_us + two.drivers_us;
    std::printf("%6d %12.4f %12.4f %8.2f\n", n, p1, p2, p1 / p2);
  }
  return 0;
}
