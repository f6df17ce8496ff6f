// The measurements sensors produce: each one's check that its numbers are finite, and each as JSON.
#include "base/json.hpp"

#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <utility>

namespace ssx {

namespace {

void appendArray(std::string& out, const char* name, std::initializer_list<double> values) {
  out += '"';
  out += name;
  out += "\":[";
  bool first = true;
  for (const double v : values) {
    if (!first) out += ',';
    first = false;
    detail::appendNumber(out, v);
  }
  out += ']';
}

}  // namespace

std::string measurementJson(const Measurement& m, const Environment& env) {
  std::string out;
  if (const auto* imu = dynamic_cast<const ImuMeasurement*>(&m)) {
    out = R"({"kind":"imu","stamp":)";
    detail::appendNumber(out, toSeconds(m.stamp));
    out += ',';
    appendArray(out, "accelerometer", {imu->accelerometer.x(), imu->accelerometer.y(), imu->accelerometer.z()});
    out += ',';
    appendArray(out, "gyroscope", {imu->gyroscope.x(), imu->gyroscope.y(), imu->gyroscope.z()});
  } else if (const auto* pose = dynamic_cast<const PoseMeasurement*>(&m)) {
    const Pose& p = pose->pose;
    out = R"({"kind":"pose","stamp":)";
    detail::appendNumber(out, toSeconds(m.stamp));
    out += ',';
    appendArray(out, "position", {p.position.x(), p.position.y(), p.position.z()});
    out += ',';
    appendArray(out, "orientation", {p.orientation.w(), p.orientation.x(), p.orientation.y(), p.orientation.z()});
    out += ',';
    appendArray(out, "linear_velocity", {pose->linear_velocity.x(), pose->linear_velocity.y(), pose->linear_velocity.z()});
    out += ',';
    appendArray(out, "angular_velocity",
                {pose->angular_velocity.x(), pose->angular_velocity.y(), pose->angular_velocity.z()});
  } else if (const auto* range = dynamic_cast<const RangeMeasurement*>(&m)) {
    out = R"({"kind":"range","stamp":)";
    detail::appendNumber(out, toSeconds(m.stamp));
    out += range->body_frame ? R"(,"frame":"body","detections":[)" : R"(,"frame":"world","detections":[)";
    bool first = true;
    for (const auto& d : range->detections) {
      if (!first) out += ',';
      first = false;
      out += R"({"seen":)";
      detail::appendString(out, d.artifact < env.artifactCount() ? std::as_const(env).artifact(d.artifact).name()
                                                                 : std::string());
      out += d.obstacle ? R"(,"obstacle":true,)" : R"(,"obstacle":false,)";
      appendArray(out, "relative", {d.relative.x(), d.relative.y(), d.relative.z()});
      out += R"(,"distance":)";
      detail::appendNumber(out, d.distance);
      out += '}';
    }
    out += ']';
  } else {
    return {};
  }
  return out + "}";
}

Measurement::~Measurement() = default;
bool Measurement::finite() const noexcept { return true; }

ClockMeasurement::~ClockMeasurement() = default;
bool ClockMeasurement::finite() const noexcept { return std::isfinite(seconds); }
PoseMeasurement::~PoseMeasurement() = default;
bool PoseMeasurement::finite() const noexcept {
  return pose.position.allFinite() && pose.orientation.coeffs().allFinite() && linear_velocity.allFinite() &&
         angular_velocity.allFinite();
}

ImuMeasurement::~ImuMeasurement() = default;
bool ImuMeasurement::finite() const noexcept {
  return accelerometer.allFinite() && gyroscope.allFinite() && std::isfinite(accelerometer_lsb) &&
         std::isfinite(gyroscope_lsb);
}

RangeMeasurement::~RangeMeasurement() = default;
bool RangeMeasurement::finite() const noexcept {
  return std::all_of(detections.begin(), detections.end(),
                     [](const Detection& d) { return d.relative.allFinite() && std::isfinite(d.distance); });
}
ProximityMeasurement::~ProximityMeasurement() = default;
bool ProximityMeasurement::finite() const noexcept {
  return std::all_of(readings.begin(), readings.end(), [](double r) { return std::isfinite(r); });
}
GroundMeasurement::~GroundMeasurement() = default;
bool GroundMeasurement::finite() const noexcept {
  return std::all_of(readings.begin(), readings.end(), [](double r) { return std::isfinite(r); });
}
RangeBearingMeasurement::~RangeBearingMeasurement() = default;
RangeBearingInterface::~RangeBearingInterface() = default;
bool RangeBearingMeasurement::finite() const noexcept {
  return std::all_of(messages.begin(), messages.end(), [](const Message& m) {
    return std::isfinite(m.range) && std::isfinite(m.bearing) && std::isfinite(m.elevation);
  });
}
CameraMeasurement::~CameraMeasurement() = default;
// depth is +infinity where nothing was hit, by design: only the camera's pose is checked
bool CameraMeasurement::finite() const noexcept {
  return view.pose.position.allFinite() && view.pose.orientation.coeffs().allFinite();
}
}  // namespace ssx
