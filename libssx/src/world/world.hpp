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

#include "engines/state_checks.hpp"

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace ssx::detail {

/// One physic node's body, from start on (read by every state() and addForce: kept to one cache
/// line).
struct NodeData {
  Pose pose_in_body;  // node frame in the body's centre-of-mass frame
  int body = -1;      // -1: static, or not started
  int static_group = -1;  // static: its shapes' group in the engine (PhysicEngine::addStatic)
  bool is_static = false;
  bool at_body = false;  // pose_in_body is exactly the identity: the node's state is its body's
};

/// One physic node as placed before start (static nodes keep their pose).
struct NodeSetup {
  Pose pose;                           // world pose as placed
  Vec3 initial_linear = Vec3::Zero();  // of this node's origin, set before start
  Vec3 initial_angular = Vec3::Zero();
  bool velocity_set = false;  // setVelocity was called on this node before start
};

/// One joint: a child node joined to its parent's body, its frames and its motor's command.
struct JointData {
  std::uint32_t node = 0;      // the child node (its spec holds the JointSpec)
  std::uint32_t artifact = 0;
  int parent_body = -1;        // from start: -1 for the static world
  int child_body = -1;
  int engine = -1;             // the engine's index of it
  Pose in_parent;  // the joint's frame (z: its axis) in the parent body's frame (static: world)
  Pose in_child;   // in the child body's frame
  double damping = 0.0;  // as applied: at most what stops the joint in one step (explicit damping)
  double effective = 0.0;  // the inertia (kg m^2) or mass (kg) the joint moves: of both bodies together
  enum class Mode : std::uint8_t { Off, Velocity, Position };
  Mode mode = Mode::Off;  // the motor's command, held until changed
  double target = 0.0;
};

/// A joint made at run time (PhysicNode::attach): `holder`'s body holds `held`'s by a fixed joint.
struct Attachment {
  std::uint32_t holder = 0;  // node indices
  std::uint32_t held = 0;
  int engine = -1;  // the engine's index of the joint
  JointSpec::Kind kind = JointSpec::Kind::Fixed;  // fixed or ball
};

/// What a driver asked for during a step, carried out as the drivers phase ends.
struct AttachRequest {
  enum class Kind : std::uint8_t { Attach, Release, Detach };
  Kind kind = Kind::Attach;
  std::uint32_t node = 0;   // the node that asked
  std::uint32_t other = 0;  // attach: the node to hold
  JointSpec::Kind joint = JointSpec::Kind::Fixed;  // attach: fixed, or a ball at the node's origin
};

/// One attached driver or sensor: who it is and when it runs (its random stream is in
/// World::randoms, at the same index).
struct PluginSlot {
  std::uint32_t artifact = 0;
  std::uint32_t index = 0;  // 0: the driver; i + 1: sensor i
  std::int64_t period_steps = 1;
  std::string class_name;
};

/// What the sensors phase reads of one sensor (its parameters are in ArtifactModel).
struct SensorSlot {
  Sensor* sensor = nullptr;
  std::int64_t period_steps = 1;  // a copy of its plugin slot's, beside what the phase reads
  std::uint32_t plugin = 0;       // its plugin slot: where World::fresh says whether it measured
};

struct Subscription {
  std::uint32_t source = 0;        // artifact index
  std::uint32_t sensor_index = 0;  // in that artifact
  std::uint64_t sequence = 0;
  // the sensor itself and its plugin slot, so that delivering reads neither the source artifact's
  // data nor its sensor list (with thousands of robots each would be a cache miss)
  const Sensor* sensor = nullptr;
  std::uint32_t plugin = 0;
  std::function<void(const Measurement&)> callback;
};

/// One artifact's part of the model: its plugins' parameters and the instances it owns. Set before
/// start, read by configure, checks and messages; never by the phases.
struct ArtifactModel {
  std::unique_ptr<Driver> owned_driver;  // null when a ClassLoader owns it (or there is none)
  Descriptor driver_params;
  std::vector<std::unique_ptr<Sensor>> owned_sensors;  // per sensor; null when a ClassLoader owns it
  std::vector<Descriptor> sensor_params;
};

/// What the phases read and write of one artifact: its plugins, subscriptions and bodies.
struct ArtifactData {
  Driver* driver = nullptr;
  std::int64_t driver_period = 1;  // a copy of its slot's, beside what the drivers phase reads
  std::vector<SensorSlot> sensors;   // as attached (the phases read World::sensor_slots)
  std::vector<Subscription> inbox;  // until start; then in World::subscriptions
  // from start: its sensors in World::sensor_slots and its subscriptions, sorted (source, sensor,
  // sequence), in World::subscriptions, [begin, end)
  std::uint32_t sensor_begin = 0, sensor_end = 0;
  std::uint32_t inbox_begin = 0, inbox_end = 0;
  bool silent = false;             // a lost ghost: its sensors do not measure
  bool absent = false;             // out of the world (Environment::despawn): no plugin runs
  std::vector<AttachRequest> attach_requests;  // its driver's, until its drivers phase ends
  int body_begin = 0;               // bodies [body_begin, body_end) in the body arrays
  int body_end = 0;
  // where its nodes and plugin slots are in the world's tables, for prefetching: [first, end)
  // (contiguous when the artifact was built in one go, as the scene loader does)
  std::uint32_t first_node = 0;
  std::uint32_t node_end = 0;
  std::uint32_t first_slot = 0;
  std::uint32_t slot_end = 0;
};

/// A constant varied (Environment::vary): `plugin` -1 is the artifact's bodies (k 0: mass, 1:
/// inertia), else its plugin as PluginSlot::index numbers them; `k` indexes its variables.
struct Varied {
  std::int32_t plugin = 0;
  std::uint32_t k = 0;
  double value = 0;
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
  bool stepping = false;         // inside step(): its hooks, phases and listeners
  // what a saved state must match, computed once the world is built (nothing changes it then)
  std::uint64_t fingerprint = 0;
  bool fingerprint_known = false;
  // the checksum and size of the last state restored here without error: restoring the same
  // bytes again needs no copy of the state before it to fall back on (a learning environment's
  // reset, from one start state, episode after episode)
  std::uint64_t restored_checksum = 0;
  std::size_t restored_size = 0;
  mutable std::size_t state_size_hint = 0;  // the last saved state's size (saveState reserves it)
  std::int64_t steps = 0;        // steps taken
  std::int64_t current_step = 0;  // the step being taken

  // per artifact
  std::vector<std::unique_ptr<Artifact>> artifacts;
  std::vector<ArtifactData> artifact_data;
  std::vector<ArtifactModel> models;
  std::unordered_map<std::string, Artifact*> names;
  std::vector<PendingError> errors;  // filled by the parallel phases
  // the constants varied (Environment::vary), per artifact, sorted by (plugin, k); empty until
  // the first variation. Only values other than the neutral one are kept.
  std::vector<std::vector<Varied>> varied;
  std::weak_ptr<const PhysicNodeSpec> last_validated_spec;  // a tree shared by a swarm: checked once
  std::uint64_t subscription_sequence = 0;

  // per node and per plugin slot
  std::vector<NodeData> nodes;
  std::vector<NodeSetup> node_setup;
  // the handles (PhysicNode) of `nodes`, side by side at stable addresses: what a sensor or
  // driver reads its node's state through is then one run of memory for a swarm, not one heap
  // block per node (the artifacts point into it)
  std::deque<PhysicNode> node_handles;
  std::vector<JointData> joints;   // in node order
  std::vector<int> node_joint;     // per node: its joint's index in `joints`, or -1
  std::vector<Wrench> applied;     // the wrenches with the joints' damping, when there is any
  std::vector<Attachment> attachments;  // in the order made
  std::vector<std::uint16_t> attached;  // per body: run-time joints on it
  std::atomic<bool> attach_pending{false};  // some artifact has attach_requests
  PhysicEngine* engine = nullptr;           // from start
  bool record_contacts = false;             // Environment::recordContacts
  std::vector<PluginSlot> plugins;
  std::vector<Random> randoms;
  // per plugin slot, written by the sensors phase: 1 when that sensor measured in this step (one
  // byte per sensor in one array, read by the drivers phase for every subscription)
  std::vector<std::uint8_t> fresh;
  std::vector<SensorSlot> sensor_slots;      // built at start, see ArtifactData
  std::vector<Subscription> subscriptions;  // built at start, see ArtifactData

  // per body, from start on: the snapshot, the velocities before the step, the command buffers
  std::vector<BodyState> states;
  std::vector<Vec3> previous_linear;
  std::vector<Vec3> previous_angular;
  std::vector<Wrench> wrenches;
  std::vector<std::uint32_t> body_owner;  // artifact index
  std::vector<std::uint32_t> static_group_owner;  // per addStatic group: artifact index
  // per body: the largest force and torque that change its speeds by at most the speed guards in
  // one step (commands beyond them are refused before the engine sees them)
  std::vector<WrenchLimit> wrench_limits;

  bool started() const noexcept { return !states.empty(); }
  /// Node `k`'s pose as of the snapshot (before start: as placed): what PhysicNode::pose reads,
  /// for the core's loops that walk the tables rather than the handles.
  Pose nodePose(std::size_t k) const {
    const NodeData& n = nodes[k];
    if (n.body < 0 || !started()) return node_setup[k].pose;
    const Pose& body = states[static_cast<std::size_t>(n.body)].pose;
    return n.at_body ? body : body * n.pose_in_body;
  }
  ArtifactData& data(const Artifact& a) { return artifact_data[a.index()]; }
  const ArtifactData& data(const Artifact& a) const { return artifact_data[a.index()]; }
  ArtifactModel& model(const Artifact& a) { return models[a.index()]; }
  const ArtifactModel& model(const Artifact& a) const { return models[a.index()]; }
};

}  // namespace ssx::detail
