// The measurements sensors produce: each one's check that its numbers are finite, and each as JSON.
#include "base/measurement_json.hpp"

#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>

#include <algorithm>
#include <cmath>

namespace ssx {

std::string measurementJson(const Measurement& m, const Environment& env) {
  std::string out;
  if (!detail::appendMeasurementJson(out, m, env)) out.clear();
  return out;
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
