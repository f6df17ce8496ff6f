// Artifact: a handle into the world state (world.hpp): its nodes, plugins and placement.
#include "world/phase_guard.hpp"
#include "world/world.hpp"

#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>

#include <cmath>

namespace ssx {

Artifact::Artifact(detail::World& world, std::string name, std::size_t index, const Pose& placement)
    : world_(&world), env_(&world.env), name_(std::move(name)), index_(index), placement_(placement) {}

Artifact::~Artifact() = default;


void Artifact::requireSetup(const char* what) const {
  if (world_->state != Environment::State::Setup)
    throw Error("artifact '" + name_ + "': " + what + " only before the environment starts");
}

void Artifact::buildNodes(PhysicNode* parent, const PhysicNodeSpec& spec) {
  const std::size_t index = world_->nodes.size();
  detail::ArtifactData& own = world_->data(*this);
  if (own.node_end == 0) own.first_node = static_cast<std::uint32_t>(index);
  own.node_end = static_cast<std::uint32_t>(index + 1);
  detail::NodeData data;
  data.is_static = parent != nullptr ? parent->isStatic() && !spec.joint.isBody() : spec.is_static;
  world_->nodes.push_back(data);
  world_->node_joint.push_back(-1);
  if (parent != nullptr && spec.joint.isBody()) {
    world_->node_joint.back() = static_cast<int>(world_->joints.size());
    detail::JointData joint;
    joint.node = static_cast<std::uint32_t>(index);
    joint.artifact = static_cast<std::uint32_t>(index_);
    world_->joints.push_back(joint);
  }
  world_->node_setup.push_back({(parent != nullptr ? parent->pose() : placement_) * spec.pose});
  PhysicNode* node = &world_->node_handles.emplace_back(*world_, *this, spec, parent, index);
  nodes_.push_back(node);
  if (parent == nullptr) roots_.push_back(node);
  first_root_ = roots_.front();
  for (const auto& child : spec.children) buildNodes(node, child);
}

PhysicNode& Artifact::addPhysicRoot(PhysicNodeSpec spec) {
  return addPhysicRoot(std::make_shared<const PhysicNodeSpec>(std::move(spec)));
}

PhysicNode& Artifact::addPhysicRoot(std::shared_ptr<const PhysicNodeSpec> shared) {
  requireSetup("physic nodes can be added");
  if (shared == nullptr) throw Error("artifact '" + name_ + "': addPhysicRoot got no node tree");
  const PhysicNodeSpec& spec = *shared;
  // a swarm adds one tree to thousands of artifacts: it is checked once
  if (world_->last_validated_spec.lock() != shared) {
    validatePhysicTree(spec);
    world_->last_validated_spec = shared;
  }
  if (!spec.name.empty() && node(spec.name) != nullptr)
    throw ConfigError(spec.where, "artifact '" + name_ + "': duplicate physic node name '" + spec.name + "'");
  root_specs_.push_back(std::move(shared));
  const std::size_t first = nodes_.size();
  buildNodes(nullptr, *root_specs_.back());
  // each node's pose in its body, known from here on (load-time checks read it: a quadrotor's
  // rotors), from the tree's own poses: the same in every member of a swarm wherever it was
  // placed (undoing the placement would leave a rounding of it). The nodes were added parents
  // first, at consecutive indices. A body begins at the root and at each joined child.
  const std::size_t offset = nodes_[first]->nodeIndex();
  std::vector<Pose> in_top(nodes_.size() - first);  // in the node that begins its body
  std::vector<std::size_t> top(nodes_.size() - first, 0);
  for (std::size_t k = first + 1; k < nodes_.size(); ++k) {
    const PhysicNodeSpec& s = nodes_[k]->spec();
    const std::size_t up = nodes_[k]->parent()->nodeIndex() - offset;
    if (s.joint.isBody()) {
      top[k - first] = k - first;
      continue;
    }
    top[k - first] = top[up];
    in_top[k - first] = in_top[up] * s.pose;
  }
  // a dynamic body's frame is at its centre of mass (the first node's frame in it set exactly: its
  // own pose undone and redone would be off by a rounding, and a node at the centre of mass would
  // cost a transform per query)
  for (std::size_t k = first; k < nodes_.size(); ++k) {
    detail::NodeData& n = world_->nodes[offset + (k - first)];
    if (top[k - first] == k - first) {
      n.pose_in_body = n.is_static ? Pose{} : Pose{-bodyMass(nodes_[k]->spec()).center_of_mass, Quat::Identity()};
    } else {
      n.pose_in_body = world_->nodes[offset + top[k - first]].pose_in_body * in_top[k - first];
    }
    n.at_body = !n.is_static && n.pose_in_body.position == Vec3::Zero() &&
                n.pose_in_body.orientation.coeffs() == Quat::Identity().coeffs();
  }
  return *nodes_[first];
}

void Artifact::addRenderRoot(RenderNodeSpec spec) { addRenderRoot(std::make_shared<const RenderNodeSpec>(std::move(spec))); }

void Artifact::addRenderRoot(std::shared_ptr<const RenderNodeSpec> spec) {
  requireSetup("render nodes can be added");
  if (spec == nullptr) throw ConfigError({}, "artifact '" + name_ + "': null render node tree");
  if (!spec->follow.empty() && node(spec->follow) == nullptr)
    throw ConfigError({}, "artifact '" + name_ + "': render node '" + spec->name + "' follows unknown physic node '" +
                              spec->follow + "'");
  render_roots_.push_back(std::move(spec));
}

Plugin& Artifact::attach(Plugin& plugin, std::uint32_t plugin_index, std::int64_t period_steps,
                         std::string class_name, const Descriptor& params) {
  const char* kind = plugin_index == 0 ? "driver" : "sensor";
  if (period_steps < 1) throw ConfigError(params.where(), std::string(kind) + " period must be at least 1 step");
  if (plugin.attached())
    throw ConfigError(params.where(), "artifact '" + name_ + "': this " + kind + " instance belongs to artifact '" +
                                          plugin.artifact().name() + "' already; create one instance per artifact");
  detail::ArtifactData& own = world_->data(*this);
  const std::size_t at = world_->plugins.size();
  if (own.slot_end == 0) own.first_slot = static_cast<std::uint32_t>(at);
  own.slot_end = static_cast<std::uint32_t>(at + 1);
  detail::PluginSlot slot;
  slot.artifact = static_cast<std::uint32_t>(index_);
  slot.index = plugin_index;
  slot.period_steps = period_steps;
  slot.class_name = !class_name.empty() ? std::move(class_name)
                    : plugin_index == 0 ? std::string("driver")
                                        : "sensor" + std::to_string(plugin_index - 1);
  world_->plugins.push_back(std::move(slot));
  world_->randoms.emplace_back(deriveSeed(world_->settings.seed, index_, plugin_index));
  world_->fresh.push_back(0);
  plugin.bind(*world_, *this, static_cast<std::uint32_t>(world_->plugins.size() - 1), period_steps);
  return plugin;
}

Driver& Artifact::setDriver(std::unique_ptr<Driver> driver, Descriptor params, std::int64_t period_steps,
                            std::string class_name) {
  if (!driver) throw Error("artifact '" + name_ + "': setDriver given a null driver");
  Driver& d = setDriver(*driver, std::move(params), period_steps, std::move(class_name));
  world_->model(*this).owned_driver = std::move(driver);
  return d;
}

Driver& Artifact::setDriver(Driver& driver, Descriptor params, std::int64_t period_steps, std::string class_name) {
  requireSetup("a driver can be set");
  detail::ArtifactData& data = world_->data(*this);
  if (data.driver != nullptr) throw ConfigError(params.where(), "artifact '" + name_ + "' already has a driver");
  attach(driver, 0, period_steps, std::move(class_name), params);
  data.driver = &driver;
  world_->model(*this).driver_params = std::move(params);
  data.driver_period = period_steps;
  return driver;
}

Sensor& Artifact::addSensor(std::unique_ptr<Sensor> sensor, Descriptor params, std::int64_t period_steps,
                            std::string class_name) {
  if (!sensor) throw Error("artifact '" + name_ + "': addSensor given a null sensor");
  Sensor& s = addSensor(*sensor, std::move(params), period_steps, std::move(class_name));
  world_->model(*this).owned_sensors.back() = std::move(sensor);
  return s;
}

Sensor& Artifact::addSensor(Sensor& sensor, Descriptor params, std::int64_t period_steps, std::string class_name) {
  requireSetup("sensors can be added");
  detail::ArtifactData& data = world_->data(*this);
  attach(sensor, static_cast<std::uint32_t>(data.sensors.size() + 1), period_steps, std::move(class_name), params);
  data.sensors.push_back({&sensor, period_steps, static_cast<std::uint32_t>(world_->plugins.size() - 1)});
  detail::ArtifactModel& model = world_->model(*this);
  model.owned_sensors.emplace_back();
  model.sensor_params.push_back(std::move(params));
  return sensor;
}

Driver* Artifact::driver() noexcept { return world_->data(*this).driver; }
const Driver* Artifact::driver() const noexcept { return world_->data(*this).driver; }
std::size_t Artifact::sensorCount() const noexcept { return world_->data(*this).sensors.size(); }
Sensor& Artifact::sensor(std::size_t i) { return *world_->data(*this).sensors.at(i).sensor; }
const Sensor& Artifact::sensor(std::size_t i) const { return *world_->data(*this).sensors.at(i).sensor; }
const Descriptor& Artifact::driverParameters() const noexcept { return world_->model(*this).driver_params; }
const Descriptor& Artifact::sensorParameters(std::size_t i) const { return world_->model(*this).sensor_params.at(i); }

PhysicNode* Artifact::node(std::string_view name) {
  for (const auto& n : nodes_)
    if (n->name() == name) return n;
  return nullptr;
}

const PhysicNode* Artifact::node(std::string_view name) const { return const_cast<Artifact*>(this)->node(name); }

const PhysicNode& Artifact::nodeFromParameter(const Descriptor& params, std::string_view key) const {
  return const_cast<Artifact*>(this)->nodeFromParameter(params, key);
}

PhysicNode& Artifact::nodeFromParameter(const Descriptor& params, std::string_view key) {
  const std::string name = params.get<std::string>(key, "");
  if (name.empty()) {
    if (roots_.empty()) throw params.error("artifact '" + name_ + "' has no physic node");
    return *roots_.front();
  }
  PhysicNode* n = node(name);
  if (n == nullptr) {
    const auto* a = params.find(key);
    throw params.error(*a, "no physic node '" + name + "' in artifact '" + name_ + "'");
  }
  return *n;
}

}  // namespace ssx
