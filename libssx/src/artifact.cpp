#include "phase_guard.hpp"

#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>

#include <cmath>

namespace ssx {

Artifact::Artifact(Environment& env, std::string name, std::size_t index, const Pose& placement)
    : env_(&env), name_(std::move(name)), index_(index), placement_(placement) {}

Artifact::~Artifact() = default;

void Artifact::requireSetup(const char* what) const {
  if (env_->state() != Environment::State::Setup)
    throw Error("artifact '" + name_ + "': " + what + " only before the environment starts");
}

void Artifact::buildNodes(PhysicNode* parent, const PhysicNodeSpec& spec) {
  nodes_.push_back(std::unique_ptr<PhysicNode>(new PhysicNode(*this, spec, parent)));
  PhysicNode* node = nodes_.back().get();
  node->setup_pose_ = (parent != nullptr ? parent->setup_pose_ : placement_) * spec.pose;
  node->static_ = parent != nullptr ? parent->static_ : spec.is_static;
  if (parent == nullptr) roots_.push_back(node);
  for (const auto& child : spec.children) buildNodes(node, child);
}

PhysicNode& Artifact::addPhysicRoot(PhysicNodeSpec spec) {
  requireSetup("physic nodes can be added");
  validatePhysicTree(spec);
  if (!spec.name.empty() && node(spec.name) != nullptr)
    throw ConfigError(spec.where, "artifact '" + name_ + "': duplicate physic node name '" + spec.name + "'");
  root_specs_.push_back(std::make_unique<PhysicNodeSpec>(std::move(spec)));
  const std::size_t first = nodes_.size();
  buildNodes(nullptr, *root_specs_.back());
  return *nodes_[first];
}

void Artifact::addRenderRoot(RenderNodeSpec spec) {
  requireSetup("render nodes can be added");
  if (!spec.follow.empty() && node(spec.follow) == nullptr)
    throw ConfigError({}, "artifact '" + name_ + "': render node '" + spec.name + "' follows unknown physic node '" +
                              spec.follow + "'");
  render_roots_.push_back(std::move(spec));
}

Driver& Artifact::setDriver(std::unique_ptr<Driver> driver, Descriptor params, std::int64_t period_steps,
                            std::string class_name) {
  if (!driver) throw Error("artifact '" + name_ + "': setDriver given a null driver");
  Driver& d = setDriver(*driver, std::move(params), period_steps, std::move(class_name));
  owned_driver_ = std::move(driver);
  return d;
}

Driver& Artifact::setDriver(Driver& driver, Descriptor params, std::int64_t period_steps, std::string class_name) {
  requireSetup("a driver can be set");
  if (driver_ != nullptr) throw ConfigError(params.where(), "artifact '" + name_ + "' already has a driver");
  if (period_steps < 1) throw ConfigError(params.where(), "driver period must be at least 1 step");
  if (driver.artifact_ != nullptr)
    throw ConfigError(params.where(), "artifact '" + name_ + "': this driver instance belongs to artifact '" +
                                          driver.artifact_->name() + "' already; create one instance per artifact");
  driver.artifact_ = this;
  driver.period_steps_ = period_steps;
  driver.plugin_index_ = 0;
  driver.class_name_ = class_name.empty() ? std::string("driver") : std::move(class_name);
  driver.random_.reseed(deriveSeed(env_->settings().seed, index_, 0));
  driver_ = &driver;
  driver_params_ = std::move(params);
  return driver;
}

Sensor& Artifact::addSensor(std::unique_ptr<Sensor> sensor, Descriptor params, std::int64_t period_steps,
                            std::string class_name) {
  if (!sensor) throw Error("artifact '" + name_ + "': addSensor given a null sensor");
  Sensor& s = addSensor(*sensor, std::move(params), period_steps, std::move(class_name));
  sensors_.back().owned = std::move(sensor);
  return s;
}

Sensor& Artifact::addSensor(Sensor& sensor, Descriptor params, std::int64_t period_steps, std::string class_name) {
  requireSetup("sensors can be added");
  if (period_steps < 1) throw ConfigError(params.where(), "sensor period must be at least 1 step");
  if (sensor.artifact_ != nullptr)
    throw ConfigError(params.where(), "artifact '" + name_ + "': this sensor instance belongs to artifact '" +
                                          sensor.artifact_->name() + "' already; create one instance per artifact");
  const auto plugin_index = static_cast<std::uint32_t>(sensors_.size() + 1);
  sensor.artifact_ = this;
  sensor.period_steps_ = period_steps;
  sensor.plugin_index_ = plugin_index;
  sensor.class_name_ = class_name.empty() ? "sensor" + std::to_string(plugin_index - 1) : std::move(class_name);
  sensor.random_.reseed(deriveSeed(env_->settings().seed, index_, plugin_index));
  sensors_.push_back({&sensor, nullptr, std::move(params), false});
  return sensor;
}

PhysicNode* Artifact::node(std::string_view name) const {
  for (const auto& n : nodes_)
    if (n->name() == name) return n.get();
  return nullptr;
}

PhysicNode& Artifact::nodeFromParameter(const Descriptor& params, std::string_view key) const {
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

void Artifact::checkWritable() const {
  if (!detail::PhaseGuard::in_phase || detail::PhaseGuard::writer == this) return;
  const Artifact* w = detail::PhaseGuard::writer;
  std::string who = w != nullptr ? std::string(detail::PhaseGuard::role) + " of artifact '" + w->name() + "'"
                                 : std::string("a ") + detail::PhaseGuard::role;
  throw Error(who + " tried to write to artifact '" + name_ +
              "': during a step, only an artifact's own driver writes its forces and torques");
}

Wrench& Artifact::wrench(int body) { return env_->wrenches_[static_cast<std::size_t>(body)]; }

// --- PhysicNode (needs the environment's snapshot) -----------------------------------------------

BodyState PhysicNode::state() const {
  const Environment& env = artifact_->environment();
  if (body_ >= 0 && !env.states_.empty()) return env.states_[static_cast<std::size_t>(body_)].attached(pose_in_body_);
  BodyState s;
  s.pose = setup_pose_;
  if (!static_) {
    s.linear_velocity = initial_linear_;
    s.angular_velocity = initial_angular_;
  }
  return s;
}

Pose PhysicNode::pose() const {
  const Environment& env = artifact_->environment();
  if (body_ < 0 || env.states_.empty()) return setup_pose_;
  return env.states_[static_cast<std::size_t>(body_)].pose * pose_in_body_;
}

void PhysicNode::addForce(const Vec3& force, Frame force_frame, const Vec3& point, Frame point_frame) {
  artifact_->checkWritable();
  if (body_ < 0 || artifact_->environment().states_.empty())
    throw Error("artifact '" + artifact_->name() + "', node '" + name() +
                "': forces apply to dynamic nodes once the environment has started");
  if (!force.allFinite() || !point.allFinite())
    throw Error("artifact '" + artifact_->name() + "', node '" + name() + "': force or point is NaN or infinite");
  const BodyState& b = artifact_->environment().states_[static_cast<std::size_t>(body_)];
  const Pose node = b.pose * pose_in_body_;
  const Vec3 f = force_frame == Frame::World ? force : Vec3(node.orientation * force);
  const Vec3 p = point_frame == Frame::Local ? node.transformPoint(point) : point;
  Wrench& w = artifact_->wrench(body_);
  w.force += f;
  w.torque += (p - b.pose.position).cross(f);
}

void PhysicNode::addTorque(const Vec3& torque, Frame frame) {
  artifact_->checkWritable();
  if (body_ < 0 || artifact_->environment().states_.empty())
    throw Error("artifact '" + artifact_->name() + "', node '" + name() +
                "': torques apply to dynamic nodes once the environment has started");
  if (!torque.allFinite())
    throw Error("artifact '" + artifact_->name() + "', node '" + name() + "': torque is NaN or infinite");
  const Pose node = pose();
  artifact_->wrench(body_).torque += frame == Frame::World ? torque : Vec3(node.orientation * torque);
}

void PhysicNode::setVelocity(const Vec3& linear, const Vec3& angular) {
  Environment& env = artifact_->environment();
  if (detail::PhaseGuard::in_phase) throw Error("setVelocity is not allowed during a step");
  const PhysicsSettings& ps = env.settings().physics;
  if (!linear.allFinite() || !angular.allFinite() || linear.norm() > ps.max_linear_speed ||
      angular.norm() > ps.max_angular_speed)
    throw Error("artifact '" + artifact_->name() + "', node '" + name() +
                "': velocity must be finite and within max_linear_speed / max_angular_speed");
  if (env.state() == Environment::State::Setup) {
    initial_linear_ = linear;
    initial_angular_ = angular;
    return;
  }
  if (static_) throw Error("node '" + name() + "' of artifact '" + artifact_->name() + "' is static");
  if (env.state() != Environment::State::Running) throw Error("setVelocity: the environment is not running");
  BodyState& b = env.states_[static_cast<std::size_t>(body_)];
  const Vec3 r = b.pose.position - pose().position;  // node origin to centre of mass
  b.linear_velocity = linear + angular.cross(r);
  b.angular_velocity = angular;
  env.physics_->setState(body_, b);
}

}  // namespace ssx
