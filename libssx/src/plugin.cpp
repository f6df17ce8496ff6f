#include <ssx/artifact.hpp>
#include <ssx/measurements.hpp>
#include <ssx/environment.hpp>
#include <ssx/plugin.hpp>

#include <algorithm>
#include <cmath>
#include <typeinfo>

namespace ssx {

Plugin::~Plugin() = default;
void Plugin::configure(const Descriptor&, PluginSetup&) {}
void Plugin::destroy() {}
void Plugin::saveState(StateWriter&) const {}
void Plugin::loadState(StateReader&) {}

void PluginSetup::subscribe(const Sensor& sensor, std::function<void(const Measurement&)> callback) {
  env_->subscribe(sensor, env_->artifact(plugin_->artifact().index()), std::move(callback));
}

void PluginSetup::requireMeasurement(const Sensor& sensor, bool matches) const {
  if (!matches)
    throw ConfigError({}, plugin_->className() + " of artifact '" + plugin_->artifact().name() +
                              "' subscribed to sensor '" + sensor.className() + "' of artifact '" +
                              sensor.artifact().name() + "' for a measurement type it does not produce");
}

void PluginSetup::enableNeighborQueries(double cell_size) { env_->enableNeighborQueries(cell_size); }

std::shared_ptr<const void>* PluginSetup::findShared(const std::type_info& type, std::string_view key) {
  if (shared_ == nullptr) return nullptr;
  // per plugin class: two classes that happen to share a value type and a key share nothing
  return &(*shared_)[{std::type_index(typeid(*plugin_)), std::type_index(type), std::string(key)}];
}

void PluginSetup::addCameraRequest(std::function<bool(std::int64_t, CameraView&)> due, Image& target) {
  const char* kind = dynamic_cast<const Driver*>(plugin_) != nullptr ? "driver '" : "sensor '";
  env_->addCameraRequest(kind + plugin_->className() + "' of artifact '" + plugin_->artifact().name() + "'",
                         std::move(due), target);
}

Measurement::~Measurement() = default;
bool Measurement::finite() const noexcept { return true; }

SimulationExtension::~SimulationExtension() = default;
void SimulationExtension::init(Environment&, const Descriptor&) {}
void SimulationExtension::beforeStep(Environment&) {}
void SimulationExtension::afterStep(Environment&) {}
void SimulationExtension::shutdown(Environment&) {}
void SimulationExtension::saveState(StateWriter&) const {}
void SimulationExtension::loadState(StateReader&) {}

}  // namespace ssx

#include <ssx/measurements.hpp>

namespace ssx {
ClockMeasurement::~ClockMeasurement() = default;
bool ClockMeasurement::finite() const noexcept { return std::isfinite(seconds); }
PoseMeasurement::~PoseMeasurement() = default;
bool PoseMeasurement::finite() const noexcept {
  return pose.position.allFinite() && pose.orientation.coeffs().allFinite() && linear_velocity.allFinite() &&
         angular_velocity.allFinite();
}
}  // namespace ssx

namespace ssx {
ImuMeasurement::~ImuMeasurement() = default;
bool ImuMeasurement::finite() const noexcept {
  return accelerometer.allFinite() && gyroscope.allFinite() && std::isfinite(accelerometer_lsb) &&
         std::isfinite(gyroscope_lsb);
}
}  // namespace ssx

#include <ssx/metrics.hpp>
#include <ssx/setpoint.hpp>

namespace ssx {
SetpointInterface::~SetpointInterface() = default;
MetricSource::~MetricSource() = default;
}  // namespace ssx

namespace ssx {
RangeMeasurement::~RangeMeasurement() = default;
bool RangeMeasurement::finite() const noexcept {
  return std::all_of(detections.begin(), detections.end(),
                     [](const Detection& d) { return d.relative.allFinite() && std::isfinite(d.distance); });
}
CameraMeasurement::~CameraMeasurement() = default;
// depth is +infinity where nothing was hit, by design: only the camera's pose is checked
bool CameraMeasurement::finite() const noexcept {
  return view.pose.position.allFinite() && view.pose.orientation.coeffs().allFinite();
}
}  // namespace ssx
