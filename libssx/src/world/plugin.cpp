#include "world/world.hpp"

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

void PluginSetup::enableRayQueries() { env_->enableRayQueries(); }

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


SimulationExtension::~SimulationExtension() = default;
void SimulationExtension::init(Environment&, const Descriptor&) {}
void SimulationExtension::beforeStep(Environment&) {}
void SimulationExtension::afterStep(Environment&) {}
void SimulationExtension::shutdown(Environment&) {}
void SimulationExtension::saveState(StateWriter&) const {}
void SimulationExtension::loadState(StateReader&) {}

// --- Plugin: its slot in the world ---------------------------------------------------------------

void Plugin::bind(detail::World& world, Artifact& artifact, std::uint32_t slot, std::int64_t period_steps) noexcept {
  world_ = &world;
  artifact_ = &artifact;
  env_ = &world.env;
  slot_ = slot;
  period_steps_ = period_steps;
}

Random& Plugin::random() {
  if (world_ == nullptr) throw Error("random(): the plugin is not attached to an artifact yet");
  return world_->randoms[slot_];
}

const std::string& Plugin::className() const noexcept {
  static const std::string unattached = "plugin";
  return world_ != nullptr ? world_->plugins[slot_].class_name : unattached;
}

}  // namespace ssx
