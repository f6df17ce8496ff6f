// Measurements: each kind says whether its numbers are finite, so that the environment can stop a
// sensor that writes a NaN before anyone reads it; a camera's +infinity depth is no such number.
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>

#include <catch2/catch.hpp>

#include <limits>

using namespace ssx;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

TEST_CASE("measurements: a NaN or infinity in any number makes a measurement not finite", "[measurements]") {
  ClockMeasurement clock;
  CHECK(clock.finite());
  clock.seconds = kNaN;
  CHECK_FALSE(clock.finite());

  PoseMeasurement pose;
  CHECK(pose.finite());
  pose.angular_velocity.z() = kInf;
  CHECK_FALSE(pose.finite());
  pose = PoseMeasurement{};
  pose.pose.orientation.w() = kNaN;
  CHECK_FALSE(pose.finite());

  ImuMeasurement imu;
  CHECK(imu.finite());
  imu.gyroscope_lsb = kNaN;
  CHECK_FALSE(imu.finite());
  imu = ImuMeasurement{};
  imu.accelerometer.x() = -kInf;
  CHECK_FALSE(imu.finite());

  RangeMeasurement range;
  range.detections.resize(3);
  CHECK(range.finite());
  range.detections[2].distance = kNaN;
  CHECK_FALSE(range.finite());
  range.detections[2].distance = 1;
  range.detections[1].relative.y() = kInf;
  CHECK_FALSE(range.finite());
}

TEST_CASE("measurements: a camera image with depth +infinity where nothing was hit is finite, its pose must be",
          "[measurements]") {
  CameraMeasurement camera;
  camera.image.width = 2;
  camera.image.height = 1;
  camera.image.rgb.assign(6, 0);
  camera.image.depth = {1.5f, std::numeric_limits<float>::infinity()};
  CHECK(camera.finite());
  camera.view.pose.position.x() = kNaN;
  CHECK_FALSE(camera.finite());
}

TEST_CASE("measurements as JSON: IMU and range readings with their kind and stamp, none for a clock", "[measurements]") {
  const Environment env;
  ImuMeasurement imu;
  imu.stamp = 1'500'000'000;
  imu.accelerometer = Vec3(0, 0.5, 9.75);
  imu.gyroscope = Vec3(-1, 0, 0.25);
  CHECK(measurementJson(imu, env) ==
        R"({"kind":"imu","stamp":1.5,"accelerometer":[0,0.5,9.75],"gyroscope":[-1,0,0.25]})");
  RangeMeasurement range;
  range.detections.push_back({});
  range.detections.back().artifact = 7;  // not in this environment: no name
  range.detections.back().distance = 2;
  const std::string text = measurementJson(range, env);
  CHECK(text.find(R"("kind":"range")") != std::string::npos);
  CHECK(text.find(R"({"seen":"","obstacle":false,)") != std::string::npos);
  CHECK(text.find(R"("distance":2})") != std::string::npos);
  CHECK(measurementJson(ClockMeasurement{}, env).empty());
}
