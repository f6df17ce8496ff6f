// The IMU sensor: noise of its density (sample deviation and Allan deviation), +1 g upwards at rest,
// and the body's rate on the gyroscope; its counts rounded as std::llround does.
#include <ssx/ssx.hpp>

#include "../../../plugins/imu/counts.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <vector>

using namespace ssx;

namespace {

// overlapping Allan deviation of samples x at cluster size m
double allanDeviation(const std::vector<double>& x, std::size_t m) {
  std::vector<double> cum(x.size() + 1, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) cum[i + 1] = cum[i] + x[i];
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i + 2 * m <= x.size(); ++i) {
    const double a = (cum[i + m] - cum[i]) / m, b = (cum[i + 2 * m] - cum[i + m]) / m;
    sum += (b - a) * (b - a);
    ++n;
  }
  return std::sqrt(sum / (2.0 * n));
}

}  // namespace

TEST_CASE("IMU noise matches its density: sample std and Allan deviation", "[quadrotor][imu]") {
  // a body at rest in zero gravity: true rates and specific force are zero. Sensor 0 has the
  // spec's figures; sensor 2 the same accelerometer without its bias random walk.
  const std::string xml = R"(<scene><environment timestep="0.002" seed="21"/><physics gravity="0 0 0"/>
    <type name="box" file="imu_box.xml"/><artifact name="b" type="box"/></scene>)";
  const std::filesystem::path artifact_dir = std::filesystem::path(SSX_TEST_DATA_DIR) / "valid";
  auto record = [&](std::uint64_t seed, int n, std::size_t sensor, bool accel) {
    SceneOptions o;
    o.seed = seed;
    Scene s = loadSceneFromString(xml, "imu.xml", artifact_dir, o);
    Environment& env = *s.environment;
    env.start();
    const auto& imu = dynamic_cast<const ImuMeasurement&>(env.findArtifact("b")->sensor(sensor).latest());
    std::vector<Vec3> out;
    for (int i = 0; i < n; ++i) {
      env.step();
      out.push_back(accel ? imu.accelerometer : imu.gyroscope);
    }
    return out;
  };
  const int n = 200000;  // 400 s at 500 Hz
  const double dt = 0.002;
  auto stats = [&](const std::vector<Vec3>& samples, int axis, double& std, double& adev1) {
    std::vector<double> x;
    for (const auto& v : samples) x.push_back(v[axis]);
    double mean = 0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(x.size());
    double var = 0;
    for (double v : x) var += (v - mean) * (v - mean);
    std = std::sqrt(var / static_cast<double>(x.size() - 1));
    adev1 = allanDeviation(x, static_cast<std::size_t>(1.0 / dt));
  };
  // white noise: std = N / sqrt(dt) within 5 %, Allan(1 s) = N within 10 %
  auto checkWhite = [&](const std::vector<Vec3>& samples, double density, const char* what) {
    for (int axis = 0; axis < 3; ++axis) {
      double std = 0, adev = 0;
      stats(samples, axis, std, adev);
      INFO(what << " axis " << axis << ": std " << std << " (expected " << density / std::sqrt(dt) << "), Allan(1 s) "
                << adev << " (expected " << density << ")");
      CHECK(std / (density / std::sqrt(dt)) == Approx(1.0).margin(0.05));
      CHECK(adev / density == Approx(1.0).margin(0.10));
    }
  };
  const auto gyro = record(21, n, 0, false);
  checkWhite(gyro, 3.394e-4, "gyro (spec figures)");
  checkWhite(record(21, n, 2, true), 4.0e-3, "accel without bias random walk");
  // with the spec's accelerometer bias random walk K = 6e-3, Allan(1 s) = sqrt(N^2 + K^2 / 3)
  const auto accel = record(21, n, 0, true);
  for (int axis = 0; axis < 3; ++axis) {
    double std = 0, adev = 0;
    stats(accel, axis, std, adev);
    CHECK(adev / std::sqrt(4.0e-3 * 4.0e-3 + 6.0e-3 * 6.0e-3 / 3.0) == Approx(1.0).margin(0.10));
  }
  // the same seed gives the same samples, another seed others
  const auto again = record(21, 1000, 0, false);
  for (std::size_t i = 0; i < 1000; ++i) REQUIRE(again[i] == gyro[i]);
  CHECK(record(22, 10, 0, false)[5] != gyro[5]);
}

TEST_CASE("the accelerometer reads +1 g upwards at rest and the gyroscope the body rate", "[quadrotor][imu]") {
  const std::string xml = R"(<scene><environment timestep="0.002"/><ground/>
    <type name="box" file="imu_box.xml"/><artifact name="b" type="box" xyz="0 0 0.05"/></scene>)";
  Scene s = loadSceneFromString(xml, "imu.xml", std::filesystem::path(SSX_TEST_DATA_DIR) / "valid");
  Environment& env = *s.environment;
  env.step(500);
  const auto& imu = dynamic_cast<const ImuMeasurement&>(env.findArtifact("b")->sensor(1).latest());
  CHECK(imu.accelerometer.z() == Approx(9.81).margin(0.02));
  CHECK(std::abs(imu.accelerometer.x()) < 0.02);
  CHECK(imu.accelerometer_counts[2] == std::llround(imu.accelerometer.z() / imu.accelerometer_lsb));
}

TEST_CASE("an IMU's counts are rounded as std::llround rounds, halves away from zero", "[imu]") {
  using ssx::plugins::roundCounts;
  // the halves and their neighbours one ulp either side, both signs, and numbers spread over the range
  for (const double whole : {0.0, 1.0, 2.0, 3.0, 1023.0, 8388607.0, 16777215.0}) {
    const double half = whole + 0.5;
    for (const double x :
         {half, std::nextafter(half, 0.0), std::nextafter(half, 1e9), whole, std::nextafter(whole, 1e9)}) {
      CHECK(roundCounts(x) == std::llround(x));
      CHECK(roundCounts(-x) == std::llround(-x));
    }
  }
  CHECK(roundCounts(0.49999999999999994) == 0);  // (floor(x + 0.5) would say 1)
  CHECK(roundCounts(-2.5) == -3);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> spread(-16777216.0, 16777216.0);
  for (int i = 0; i < 100000; ++i) {
    const double x = spread(rng);
    REQUIRE(roundCounts(x) == std::llround(x));
  }
}
