// ssx_bench_quadrotor: cost of the quadrotor driver and its IMU per quadrotor per step.
//
// N mk_quads (examples/artifacts/mk_quad.xml: quadrotor driver, IMU, pose sensor) hover on a grid
// at 500 Hz; prints, per quadrotor per step, the medians of the sensors phase (IMU + pose) and the
// drivers phase (motor model, inner loop every step, outer loop every 10th), on 1 and 2 threads.
// usage: ssx_bench_quadrotor [--quick]
#include <ssx/ssx.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

double medianUs(const ssx::TimingRecorder& t, ssx::Nanoseconds ssx::StepTiming::*field, int n) {
  std::vector<ssx::Nanoseconds> v;
  for (const auto& s : t.samples()) v.push_back(s.*field);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return static_cast<double>(v[v.size() / 2]) * 1e-3 / n;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::printf("# per quadrotor per step at 500 Hz (us); target: driver + IMU <= 1 us\n");
  std::printf("%6s %7s %10s %10s %10s %12s\n", "N", "threads", "sensors", "drivers", "physics", "drv+sensors");
  for (int n : quick ? std::vector<int>{100} : std::vector<int>{100, 1000, 10000}) {
    for (int threads : {1, 2}) {
      const std::string xml = "<scene><environment timestep=\"0.002\" seed=\"1\" threads=\"" + std::to_string(threads) +
                              "\"/><type name=\"q\" file=\"mk_quad.xml\"/>"
                              "<swarm type=\"q\" count=\"" +
                              std::to_string(n) +
                              "\" name=\"q{i}\" layout=\"grid\" spacing=\"2\" xyz=\"0 0 2\"/></scene>";
      ssx::Scene scene = ssx::loadSceneFromString(xml, "bench.xml", std::string(SSX_EXAMPLES_DIR) + "/artifacts");
      ssx::Environment& env = *scene.environment;
      env.step(50);
      env.timing().clear();
      env.step(std::clamp(200000 / n, 50, 2000));
      const double sensors = medianUs(env.timing(), &ssx::StepTiming::sensors, n);
      const double drivers = medianUs(env.timing(), &ssx::StepTiming::drivers, n);
      const double physics = medianUs(env.timing(), &ssx::StepTiming::physics, n);
      std::printf("%6d %7d %10.3f %10.3f %10.3f %12.3f\n", n, threads, sensors, drivers, physics, sensors + drivers);
    }
  }
  return 0;
}
