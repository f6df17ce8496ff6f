#pragma once
// The world state: everything about a populated environment that the phases read and write, in
// arrays indexed by artifact, node, plugin slot and body. The public classes are handles into it:
// an Artifact is its index here, a PhysicNode its node index, a Plugin its slot. Only the core's
// .cpp files include this header; nothing outside libssx can name its members.
//
// What a scene defines and never changes after start (node specs, render trees, plugin parameter
// values with their declarations) stays with the Artifact handles and their Descriptors: the model.

#include <ssx/artifact.hpp>
#include <ssx/descriptor.hpp>
#include <ssx/environment.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/plugin.hpp>
#include <ssx/random.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace ssx::detail {

/// One physic node's placement and, from start on, its body.
struct NodeData {
  int body = -1;  // -1: static, or not started
  bool is_static = false;
  Pose pose_in_body;                   // node frame in the body's centre-of-mass frame
  Pose setup_pose;                     // world pose as placed (static nodes keep it)
  Vec3 initial_linear = Vec3::Zero();  // of this node's origin, set before start
  Vec3 initial_angular = Vec3::Zero();
};

/// One attached driver or sensor: who it is, when it runs, its random stream.
struct PluginSlot {
  std::uint32_t artifact = 0;
  std::uint32_t index = 0;  // 0: the driver; i + 1: sensor i
  std::int64_t period_steps = 1;
  std::string class_name;
  Random random;
};

struct SensorSlot {
  Sensor* sensor = nullptr;
  std::unique_ptr<Sensor> owned;  // null when a ClassLoader owns it
  Descriptor params;
  std::int64_t period_steps = 1;  // a copy of its slot's, beside what the sensors phase reads
  bool fresh = false;             // wrote a measurement in this step
};

struct Subscription {
  std::uint32_t source = 0;        // artifact index
  std::uint32_t sensor_index = 0;  // in that artifact
  std::uint64_t sequence = 0;
  std::function<void(const Measurement&)> callback;
};

/// One artifact's plugins, its subscriptions and its bodies.
struct ArtifactData {
  Driver* driver = nullptr;
  std::unique_ptr<Driver> owned_driver;  // null when a ClassLoader owns it
  Descriptor driver_params;
  std::int64_t driver_period = 1;  // a copy of its slot's, beside what the drivers phase reads
  std::vector<SensorSlot> sensors;
  std::vector<Subscription> inbox;  // sorted (source, sensor, sequence) at start
  int body_begin = 0;               // bodies [body_begin, body_end) in the body arrays
  int body_end = 0;
};

struct PendingError {
  std::string plugin;
  std::string message;
};

struct World {
  World(Environment& environment, const EnvironmentSettings& settings) : env(environment), settings(settings) {}

  Environment& env;
  const EnvironmentSettings& settings;
  Environment::State state = Environment::State::Setup;
  bool configuring = false;      // plugins' configure is running
  std::int64_t steps = 0;        // steps taken
  std::int64_t current_step = 0;  // the step being taken

  // per artifact
  std::vector<std::unique_ptr<Artifact>> artifacts;
  std::vector<ArtifactData> artifact_data;
  std::unordered_map<std::string, Artifact*> names;
  std::vector<PendingError> errors;  // filled by the parallel phases
  std::uint64_t subscription_sequence = 0;

  // per node and per plugin slot
  std::vector<NodeData> nodes;
  std::vector<PluginSlot> plugins;

  // per body, from start on: the snapshot, the velocities before the step, the command buffers
  std::vector<BodyState> states;
  std::vector<Vec3> previous_linear;
  std::vector<Vec3> previous_angular;
  std::vector<Wrench> wrenches;
  std::vector<std::uint32_t> body_owner;  // artifact index

  bool started() const noexcept { return !states.empty(); }
  ArtifactData& data(const Artifact& a) { return artifact_data[a.index()]; }
  const ArtifactData& data(const Artifact& a) const { return artifact_data[a.index()]; }
};

}  // namespace ssx::detail
