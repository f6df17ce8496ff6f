#pragma once
/// @file
/// What users write: drivers (behaviour), sensors (measurements) and simulation extensions
/// (bridges to the outside). Instances are created by the embedding program or, later, loaded
/// from plugin libraries; the code is the same.

#include <ssx/descriptor.hpp>
#include <ssx/export.hpp>
#include <ssx/random.hpp>
#include <ssx/shared_value.hpp>
#include <ssx/state.hpp>
#include <ssx/types.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <typeindex>
#include <typeinfo>
#include <utility>

namespace ssx {

class Artifact;
class Environment;
class PluginSetup;
class Sensor;
struct Image;
struct CameraView;
struct Measurement;
namespace detail {
struct World;
}

/// What a driver or sensor is told about the step it runs in.
struct StepInfo {
  std::int64_t step = 0;   ///< index of the current step, from 0
  Nanoseconds time = 0;    ///< simulated time after this step's physics
  Nanoseconds period = 0;  ///< time between two runs of this plugin (period_steps * timestep)
  /// The period in seconds.
  double periodSeconds() const { return toSeconds(period); }
};

/// Common base of drivers and sensors: the artifact it belongs to, its random stream and period.
class SSX_EXPORT Plugin {
 public:
  Plugin() = default;
  Plugin(const Plugin&) = delete;
  Plugin& operator=(const Plugin&) = delete;
  virtual ~Plugin();

  /// Called once when the environment starts, after the engines are configured and the first
  /// snapshot is published, on the thread that starts the environment; artifact by artifact,
  /// each artifact's sensors before its driver. `params` are this instance's parameters (from the
  /// artifact file, or given in code), already checked against the class's declarations.
  /// `setup` is what only configure may do: subscribe to sensors, enable neighbour queries,
  /// request camera images; it is valid during this call only. Throw ConfigError (use
  /// `params.error(...)`) for what the declarations cannot say.
  virtual void configure(const Descriptor& params, PluginSetup& setup);
  /// Called once when the environment stops, before the engines stop.
  virtual void destroy();
  /// Writes what this plugin keeps between its runs and what it depends on (see ssx/state.hpp),
  /// for Environment::saveState. Its random stream is saved for it. Default: nothing.
  virtual void saveState(StateWriter& out) const;
  /// Reads back what saveState wrote, in the same order, into a plugin configured from the same
  /// scene. Default: nothing.
  virtual void loadState(StateReader& in);

  /// The artifact this plugin belongs to, read-only (a Driver gets it writable: see there).
  const Artifact& artifact() const noexcept { return *artifact_; }
  /// The environment of that artifact, read-only.
  const Environment& environment() const noexcept { return *env_; }
  /// This instance's random stream, seeded from (scene seed, artifact index, plugin index):
  /// the same numbers whatever the number of threads. Use it only inside this plugin's calls.
  /// Kept in the world state (saved and restored with it). Throws before the plugin is attached.
  Random& random();
  /// Runs every this many steps (1 before the plugin is attached).
  std::int64_t periodSteps() const noexcept { return period_steps_; }
  /// A name for messages: the class name given when attached.
  const std::string& className() const noexcept;
  /// Whether this instance is attached to an artifact.
  bool attached() const noexcept { return world_ != nullptr; }

  /// Done by Artifact::setDriver / addSensor (the world is the core's and cannot be named
  /// outside it): binds this instance to its slot.
  void bind(detail::World& world, Artifact& artifact, std::uint32_t slot, std::int64_t period_steps) noexcept;

 private:
  detail::World* world_ = nullptr;
  Artifact* artifact_ = nullptr;
  const Environment* env_ = nullptr;
  std::uint32_t slot_ = 0;
  std::int64_t period_steps_ = 1;  // as in its slot (fixed when attached)
};

/// The behaviour of an artifact: a flight controller, a door. At most one per artifact.
///
/// `step` runs in the drivers phase (after physics and sensors, in parallel over artifacts), on
/// any worker thread. It may read any artifact's state (the snapshot) and this artifact's
/// sensors; it writes only its own artifact (forces and torques through its PhysicNodes).
/// Its command buffer is cleared right before `step`, and what it writes is applied in every
/// physics step until its next run (zero-order hold).
class SSX_EXPORT Driver : public Plugin {
 public:
  /// Runs the controller once: reads sensors and the snapshot, writes this artifact's forces and
  /// torques. Called every periodSteps() steps, in the drivers phase. Throw to stop the run (a
  /// StepError names the artifact and driver).
  virtual void step(const StepInfo& info) = 0;
  /// Its own artifact, writable: its nodes take this driver's forces and torques.
  Artifact& artifact() const noexcept { return const_cast<Artifact&>(Plugin::artifact()); }
};

/// Base of every measurement a sensor delivers; `stamp` is the simulated time it was taken.
struct SSX_EXPORT Measurement {
  Nanoseconds stamp = 0;  ///< simulated time it was taken, ns
  virtual ~Measurement();
  /// Whether every number in it is finite. The core calls this after each `sense`: a NaN or an
  /// infinity stops the step with an error naming the artifact and the sensor, as a driver's NaN
  /// force does. Measurement types with floating-point fields override it.
  virtual bool finite() const noexcept;
};

/// Produces measurements from the simulated world.
///
/// `sense` runs in the sensors phase (after physics, before drivers, in parallel over
/// artifacts), on any worker thread. It reads the snapshot and writes only its own measurement
/// buffer. Subscribed callbacks then receive the measurement in the drivers phase, on the
/// subscriber artifact's thread, in a fixed order.
class SSX_EXPORT Sensor : public Plugin {
 public:
  /// Takes one measurement into its buffer. Called every periodSteps() steps, in the sensors
  /// phase. Throw to stop the run (a StepError names the artifact and sensor).
  virtual void sense(const StepInfo& info) = 0;
  /// The last measurement written by `sense` (never null).
  virtual const Measurement& latest() const = 0;
};

/// A sensor whose measurements are of type M (derived from Measurement).
template <class M>
class SensorOf : public Sensor {
 public:
  using MeasurementType = M;  ///< the type of what it measures
  /// The last measurement, typed.
  const M& value() const noexcept { return measurement_; }
  const Measurement& latest() const override { return measurement_; }

 protected:
  /// The buffer `sense` writes.
  M& output() noexcept { return measurement_; }

 private:
  M measurement_{};
};

/// What a driver or sensor may do only while it is configured: the calls that change what the
/// parallel phases read. Handed to Plugin::configure, valid during that call only.
class SSX_EXPORT PluginSetup {
 public:
  /// What the environment keeps for PluginSetup::shared while it starts.
  using SharedValues =
      std::map<std::tuple<std::type_index, std::type_index, std::string>, std::shared_ptr<const void>>;

  /// Made by the environment for `plugin`'s configure; `shared` is its table of shared values
  /// (null: nothing is shared).
  PluginSetup(Environment& environment, Plugin& plugin, SharedValues* shared = nullptr) noexcept
      : env_(&environment), plugin_(&plugin), shared_(shared) {}
  PluginSetup(const PluginSetup&) = delete;
  PluginSetup& operator=(const PluginSetup&) = delete;

  /// The environment being started, read-only.
  const Environment& environment() const noexcept { return *env_; }
  /// Delivers `sensor`'s fresh measurements to `callback`, in the drivers phase, on the thread of
  /// this plugin's artifact (which receives them).
  void subscribe(const Sensor& sensor, std::function<void(const Measurement&)> callback);
  /// Typed form: the sensor's measurement must be an M (checked now).
  template <class M>
  void subscribe(const Sensor& sensor, std::function<void(const M&)> callback);
  /// Turns the environment's neighbour queries on (Environment::neighbors), with cells of at most
  /// `cell_size` m.
  void enableNeighborQueries(double cell_size);
  /// Turns the environment's ray queries on (Environment::castRays).
  void enableRayQueries();
  /// Asks for camera images (Environment::addCameraRequest), named after this plugin.
  void addCameraRequest(std::function<bool(std::int64_t step, CameraView& view)> due, Image& target);
  /// What the instances of a class compute alike, computed once: `make()`'s result (a T, or a
  /// pointer to one) for the first instance of this plugin's class that asks for a T under `key`
  /// while the environment starts, the same object for every later one (a swarm's members,
  /// configured one after another). `key` must hold everything the value is computed from: the parameters' text, and
  /// the artifact's type where it matters. The environment lets go of the values once it has
  /// started; the instances keep what they hold. Without an environment's table (a PluginSetup
  /// made in code) every call makes its own.
  template <class T, class Make>
  std::shared_ptr<const T> shared(std::string_view key, Make&& make);

 private:
  void requireMeasurement(const Sensor& sensor, bool matches) const;
  std::shared_ptr<const void>* findShared(const std::type_info& type, std::string_view key);
  Environment* env_;
  Plugin* plugin_;
  SharedValues* shared_;
};

template <class T, class Make>
std::shared_ptr<const T> PluginSetup::shared(std::string_view key, Make&& make) {
  return detail::sharedValue<T>(findShared(typeid(T), key), std::forward<Make>(make));
}

/// A bridge to the outside world (ROS, a logger, a network link). Runs on the thread that calls
/// Environment::start/step/stop.
///
/// Order: every extension's `init` runs before the engines are configured and started, in the
/// order they were added; `shutdown` runs after the engines stopped, in reverse order (first in,
/// last out). Drivers and sensors can look an extension up by name.
class SSX_EXPORT SimulationExtension {
 public:
  SimulationExtension() = default;
  SimulationExtension(const SimulationExtension&) = delete;
  SimulationExtension& operator=(const SimulationExtension&) = delete;
  virtual ~SimulationExtension();

  /// Called once as the environment starts, before the engines; `params` are the extension's
  /// attributes. Throw ConfigError to refuse them (nothing has run yet).
  virtual void init(Environment& env, const Descriptor& params);
  /// Before each step's physics.
  virtual void beforeStep(Environment& env);
  /// After each step (drivers done, frame drawn if due).
  virtual void afterStep(Environment& env);
  /// Called once as the environment stops, after the engines. Throw Error when something could
  /// not be finished (a file not written to its end): stop() reports it.
  virtual void shutdown(Environment& env);
  /// As Plugin::saveState / loadState, for what an extension keeps between steps.
  virtual void saveState(StateWriter& out) const;
  /// @copydoc saveState
  virtual void loadState(StateReader& in);
};

template <class M>
void PluginSetup::subscribe(const Sensor& sensor, std::function<void(const M&)> callback) {
  requireMeasurement(sensor, dynamic_cast<const M*>(&sensor.latest()) != nullptr);
  subscribe(sensor, [cb = std::move(callback)](const Measurement& m) { cb(static_cast<const M&>(m)); });
}

}  // namespace ssx
