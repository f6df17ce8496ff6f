// Joints: made in the engine at start from the node trees, measured from the snapshot, their
// motors commanded and their damping applied before each physics step (see world.hpp, JointData).
#include "world/phase_guard.hpp"
#include "world/phases.hpp"
#include "world/world.hpp"

#include <ssx/environment.hpp>
#include <ssx/physic_node.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ssx {

namespace detail {

namespace {

constexpr double kPi = std::numbers::pi;

double wrapAngle(double a) {
  a = std::remainder(a, 2 * kPi);
  return a <= -kPi ? a + 2 * kPi : a;
}

const BodyState& stateOf(const World& world, int body) { return world.states[static_cast<std::size_t>(body)]; }

// the joint's frame as fixed in the parent (static: the world) and in the child, world frame
Pose parentFrame(const World& world, const JointData& j) {
  return j.parent_body < 0 ? j.in_parent : stateOf(world, j.parent_body).pose * j.in_parent;
}

// the velocity of the point `p` (world) moving with `body` (-1: the static world)
Vec3 velocityAt(const World& world, int body, const Vec3& p) {
  if (body < 0) return Vec3::Zero();
  const BodyState& s = stateOf(world, body);
  return s.linear_velocity + s.angular_velocity.cross(p - s.pose.position);
}

Vec3 angularOf(const World& world, int body) { return body < 0 ? Vec3::Zero() : stateOf(world, body).angular_velocity; }

// a joint axis' effective inertia (hinge: kg m^2 about the axis) or mass (slider: kg) for one body
double effective(const MassProperties& m, const Vec3& axis_in_body, bool angular) {
  if (angular) return 1.0 / axis_in_body.dot(m.inertia.inverse() * axis_in_body);
  return m.mass;
}

}  // namespace

double jointPosition(const World& world, const JointData& j) {
  if (!world.started()) return 0.0;
  const Pose p = parentFrame(world, j);
  const Pose c = stateOf(world, j.child_body).pose * j.in_child;
  const PhysicNodeSpec& spec = world.node_handles[j.node].spec();
  if (spec.joint.kind == JointSpec::Kind::Slider) return (p.inverse() * c).position.z();
  // the child frame's rotation relative to the parent's, about their common z axis
  Quat d = p.orientation.conjugate() * c.orientation;
  return wrapAngle(2 * std::atan2(d.z(), d.w()));
}

double jointVelocity(const World& world, const JointData& j) {
  if (!world.started()) return 0.0;
  const Pose p = parentFrame(world, j);
  const Vec3 axis = p.orientation * Vec3::UnitZ();
  const PhysicNodeSpec& spec = world.node_handles[j.node].spec();
  if (spec.joint.kind == JointSpec::Kind::Slider) {
    const Vec3 at = (stateOf(world, j.child_body).pose * j.in_child).position;
    return axis.dot(velocityAt(world, j.child_body, at) - velocityAt(world, j.parent_body, at));
  }
  return axis.dot(angularOf(world, j.child_body) - angularOf(world, j.parent_body));
}

void buildJoints(World& world, PhysicEngine& engine) {
  const double dt = toSeconds(world.settings.timestep);
  world.attached.assign(engine.bodyCount(), 0);
  for (JointData& j : world.joints) {
    const PhysicNode& node = world.node_handles[j.node];
    const JointSpec& spec = node.spec().joint;
    // the joint's frame where the tree was placed: at the child's origin, z along the axis
    const Pose child_pose = world.node_setup[j.node].pose;
    Pose frame = child_pose;
    if (spec.hasPosition())
      frame.orientation = (child_pose.orientation * Quat::FromTwoVectors(Vec3::UnitZ(), spec.axis)).normalized();
    const PhysicNode& parent = *node.parent();
    j.child_body = world.nodes[j.node].body;
    j.parent_body = world.nodes[parent.nodeIndex()].body;
    const Pose child_body = world.node_setup[j.node].pose * world.nodes[j.node].pose_in_body.inverse();
    j.in_child = child_body.inverse() * frame;
    if (j.parent_body < 0) {
      j.in_parent = frame;
    } else {
      const Pose parent_body =
          world.node_setup[parent.nodeIndex()].pose * world.nodes[parent.nodeIndex()].pose_in_body.inverse();
      j.in_parent = parent_body.inverse() * frame;
    }
    EngineJoint e;
    e.kind = spec.kind;
    e.parent = j.parent_body;
    e.child = j.child_body;
    if (j.parent_body < 0) e.static_group = world.nodes[parent.nodeIndex()].static_group;
    e.frame = frame;
    e.lower = spec.lower;
    e.upper = spec.upper;
    j.engine = engine.addJoint(e);
    // the inertia or mass the joint moves (its axis is fixed in both bodies: the same in every
    // configuration), for its damping and its position servo
    if (spec.hasPosition()) {
      const bool angular = spec.kind == JointSpec::Kind::Hinge;
      // (a body's frame has its first node's axes, in which bodyMass gives the inertia)
      double inverse = 1.0 / effective(bodyMass(node.spec()), j.in_child.orientation * Vec3::UnitZ(), angular);
      if (j.parent_body >= 0) {
        const PhysicNode* top = &parent;
        while (top->parent() != nullptr && !top->spec().joint.isBody()) top = top->parent();
        inverse += 1.0 / effective(bodyMass(top->spec()), j.in_parent.orientation * Vec3::UnitZ(), angular);
      }
      j.effective = 1.0 / inverse;
    }
    // explicit damping is stable while it takes no more than the joint's momentum in one step
    j.damping = spec.hasPosition() ? std::min(spec.damping, j.effective / dt) : 0.0;
  }
}

const Wrench* applyJoints(World& world, PhysicEngine& engine) {
  const double dt = toSeconds(world.settings.timestep);
  bool damped = false;
  for (const JointData& j : world.joints) {
    if (j.damping > 0) damped = true;
    const JointSpec& spec = world.node_handles[j.node].spec().joint;
    if (j.mode == JointData::Mode::Off) {
      // (the engine's motor is off until commanded); friction brakes the joint with the motor
      if (spec.friction > 0) engine.setJointMotor(j.engine, 0.0, spec.friction);
      continue;
    }
    double velocity = j.target;
    if (j.mode == JointData::Mode::Position) {
      // the velocity that reaches the target at the step's end, but no faster than the motor can
      // still stop from at half its effort (the rest for what loads the joint): it arrives, not overshoots
      double error = j.target - jointPosition(world, j);
      if (spec.kind == JointSpec::Kind::Hinge) error = wrapAngle(error);
      const double braking = 0.5 * spec.max_effort / j.effective;
      velocity = std::copysign(std::min(std::abs(error) / dt, std::sqrt(2 * braking * std::abs(error))), error);
    }
    velocity = std::clamp(velocity, -spec.max_velocity, spec.max_velocity);
    engine.setJointMotor(j.engine, velocity, spec.max_effort);
  }
  if (!damped) return world.wrenches.data();
  // the drivers' wrenches stay as they gave them (held over their period): damping goes on a copy
  world.applied = world.wrenches;
  for (const JointData& j : world.joints) {
    if (j.damping <= 0) continue;
    const Pose frame = parentFrame(world, j);
    const Vec3 axis = frame.orientation * Vec3::UnitZ();
    const double effort = -j.damping * jointVelocity(world, j);
    Wrench& child = world.applied[static_cast<std::size_t>(j.child_body)];
    Wrench* parent = j.parent_body >= 0 ? &world.applied[static_cast<std::size_t>(j.parent_body)] : nullptr;
    if (world.node_handles[j.node].spec().joint.kind == JointSpec::Kind::Hinge) {
      child.torque += effort * axis;
      if (parent != nullptr) parent->torque -= effort * axis;
      continue;
    }
    // a slider's force acts at the joint's origin on the child, and back on the parent there
    const Vec3 at = (stateOf(world, j.child_body).pose * j.in_child).position;
    const Vec3 f = effort * axis;
    child.force += f;
    child.torque += (at - stateOf(world, j.child_body).pose.position).cross(f);
    if (parent != nullptr) {
      parent->force -= f;
      parent->torque -= (at - stateOf(world, j.parent_body).pose.position).cross(f);
    }
  }
  return world.applied.data();
}

}  // namespace detail

namespace {

const detail::JointData& jointOf(const detail::World& world, std::size_t node, const PhysicNode& handle) {
  const int j = world.node_joint[node];
  if (j < 0 || !handle.joint().hasPosition())
    throw Error("artifact '" + handle.artifact().name() + "', node '" + handle.name() +
                "': not joined to its parent by a hinge or slider");
  return world.joints[static_cast<std::size_t>(j)];
}

}  // namespace

double PhysicNode::jointPosition() const { return detail::jointPosition(*world_, jointOf(*world_, index_, *this)); }

double PhysicNode::jointVelocity() const { return detail::jointVelocity(*world_, jointOf(*world_, index_, *this)); }

void PhysicNode::setJointVelocity(double velocity) {
  requireWritable();
  auto& j = const_cast<detail::JointData&>(jointOf(*world_, index_, *this));
  if (!(joint().max_effort > 0))
    throw Error("artifact '" + artifact_->name() + "', node '" + name() +
                "': the joint has no motor (give it max_torque or max_force)");
  if (!std::isfinite(velocity))
    throw Error("artifact '" + artifact_->name() + "', node '" + name() + "': joint velocity is NaN or infinite");
  j.mode = detail::JointData::Mode::Velocity;
  j.target = velocity;
}

void PhysicNode::setJointPosition(double position) {
  requireWritable();
  auto& j = const_cast<detail::JointData&>(jointOf(*world_, index_, *this));
  const JointSpec& spec = joint();
  if (!(spec.max_effort > 0))
    throw Error("artifact '" + artifact_->name() + "', node '" + name() +
                "': the joint has no motor (give it max_torque or max_force)");
  if (!std::isfinite(position) || position < spec.lower || position > spec.upper)
    throw Error("artifact '" + artifact_->name() + "', node '" + name() + "': joint position " +
                std::to_string(position) + " is not finite or outside the joint's limits");
  j.mode = detail::JointData::Mode::Position;
  j.target = position;
}

}  // namespace ssx
