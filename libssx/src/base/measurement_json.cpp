// A measurement as JSON, appended to a string (base/measurement_json.hpp).
#include "base/measurement_json.hpp"

#include "base/json.hpp"

#include <ssx/environment.hpp>

#include <initializer_list>
#include <utility>

namespace ssx::detail {

namespace {

void appendArray(std::string& out, const char* name, std::initializer_list<double> values) {
  out += '"';
  out += name;
  out += "\":[";
  bool first = true;
  for (const double v : values) {
    if (!first) out += ',';
    first = false;
    appendNumber(out, v);
  }
  out += ']';
}

}  // namespace

bool appendMeasurementJson(std::string& out, const Measurement& m, const Environment& env) {
  if (const auto* imu = dynamic_cast<const ImuMeasurement*>(&m)) {
    out += R"({"kind":"imu","stamp":)";
    appendNumber(out, toSeconds(m.stamp));
    out += ',';
    appendArray(out, "accelerometer", {imu->accelerometer.x(), imu->accelerometer.y(), imu->accelerometer.z()});
    out += ',';
    appendArray(out, "gyroscope", {imu->gyroscope.x(), imu->gyroscope.y(), imu->gyroscope.z()});
  } else if (const auto* pose = dynamic_cast<const PoseMeasurement*>(&m)) {
    const Pose& p = pose->pose;
    out += R"({"kind":"pose","stamp":)";
    appendNumber(out, toSeconds(m.stamp));
    out += ',';
    appendArray(out, "position", {p.position.x(), p.position.y(), p.position.z()});
    out += ',';
    appendArray(out, "orientation", {p.orientation.w(), p.orientation.x(), p.orientation.y(), p.orientation.z()});
    out += ',';
    appendArray(out, "linear_velocity",
                {pose->linear_velocity.x(), pose->linear_velocity.y(), pose->linear_velocity.z()});
    out += ',';
    appendArray(out, "angular_velocity",
                {pose->angular_velocity.x(), pose->angular_velocity.y(), pose->angular_velocity.z()});
  } else if (const auto* range = dynamic_cast<const RangeMeasurement*>(&m)) {
    out += R"({"kind":"range","stamp":)";
    appendNumber(out, toSeconds(m.stamp));
    out += range->body_frame ? R"(,"frame":"body","detections":[)" : R"(,"frame":"world","detections":[)";
    bool first = true;
    for (const auto& d : range->detections) {
      if (!first) out += ',';
      first = false;
      out += R"({"seen":)";
      appendString(out,
                   d.artifact < env.artifactCount() ? std::as_const(env).artifact(d.artifact).name() : std::string());
      out += d.obstacle ? R"(,"obstacle":true,)" : R"(,"obstacle":false,)";
      appendArray(out, "relative", {d.relative.x(), d.relative.y(), d.relative.z()});
      out += R"(,"distance":)";
      appendNumber(out, d.distance);
      out += '}';
    }
    out += ']';
  } else {
    return false;
  }
  out += '}';
  return true;
}

}  // namespace ssx::detail
