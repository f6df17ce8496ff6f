// The Bullet engine's joints: Bullet's hinge, slider, point-to-point and fixed constraints, their
// limits and motors (solved with the island of their bodies: bullet_contacts.cpp); joints made and
// removed between steps, saved with their frames.
#include "engines/bullet/bullet_parts.hpp"

#include "engines/articulations.hpp"

#include <ssx/error.hpp>

#include <cmath>
#include <numbers>

namespace ssx::detail {

using namespace bullet;

namespace {

btTransform toBt(const Pose& p) { return btTransform(bullet::toBt(p.orientation.normalized()), bullet::toBt(p.position)); }

void toRaw(const btTransform& t, double* out) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[3 * r + c] = t.getBasis()[r][c];
  for (int k = 0; k < 3; ++k) out[9 + k] = t.getOrigin()[k];
}

btTransform fromRaw(const double* in) {
  return btTransform(btMatrix3x3(in[0], in[1], in[2], in[3], in[4], in[5], in[6], in[7], in[8]),
                     btVector3(in[9], in[10], in[11]));
}

}  // namespace

int BulletEngine::addJoint(const EngineJoint& spec) {
  const auto count = static_cast<int>(bodies_.size());
  if (spec.child < 0 || spec.child >= count || spec.parent >= count || spec.parent == spec.child ||
      spec.kind == JointSpec::Kind::Rigid)
    throw Error("bullet: a joint needs a kind and two different bodies (or a body and the world)");
  if (spec.run_time)
    seal();
  else if (sealed_)
    throw Error("bullet: the scene's joints come before any step and any run-time joint");
  const btRigidBody& child = *bodies_[static_cast<std::size_t>(spec.child)]->rb;
  // the joint's frame in each body (Bullet's body frame: the centre of mass on principal axes);
  // the static world's body is at the origin
  const btTransform frame = toBt(spec.frame);
  Joint joint;
  joint.spec = spec;
  toRaw(child.getCenterOfMassTransform().inverse() * frame, joint.in_child);
  toRaw(spec.parent >= 0 ? bodies_[static_cast<std::size_t>(spec.parent)]->rb->getCenterOfMassTransform().inverse() * frame
                         : frame,
        joint.in_parent);
  makeConstraint(joint);
  // a run-time joint takes the first slot one let go of
  const std::size_t slot = placeJoint(joints_, std::move(joint), scene_joints_, sealed_);
  ++live_joints_;
  labels_stale_ = true;
  return static_cast<int>(slot);
}

void BulletEngine::makeConstraint(Joint& joint) {
  const EngineJoint& spec = joint.spec;
  btRigidBody& child = *bodies_[static_cast<std::size_t>(spec.child)]->rb;
  btRigidBody& parent =
      spec.parent >= 0 ? *bodies_[static_cast<std::size_t>(spec.parent)]->rb : btTypedConstraint::getFixedBody();
  const btTransform in_child = fromRaw(joint.in_child);
  const btTransform in_parent = fromRaw(joint.in_parent);
  switch (spec.kind) {
    case JointSpec::Kind::Hinge: {
      // the frames' z axes are the hinge's; Bullet's angle is its first body's relative to its
      // second: the child's
      auto hinge = std::make_unique<btHingeConstraint>(child, parent, in_child, in_parent);
      if (std::isfinite(spec.lower) || std::isfinite(spec.upper))
        hinge->setLimit(std::isfinite(spec.lower) ? spec.lower : -std::numbers::pi,
                        std::isfinite(spec.upper) ? spec.upper : std::numbers::pi);
      joint.constraint = std::move(hinge);
      break;
    }
    case JointSpec::Kind::Slider: {
      // Bullet's slider runs along the frames' x axes: turn z onto x; its position is the second
      // body's relative to the first, along the first's axis
      const btTransform z_to_x(btQuaternion(btVector3(0, 1, 0), -std::numbers::pi / 2));
      auto slider = std::make_unique<btSliderConstraint>(parent, child, in_parent * z_to_x, in_child * z_to_x, true);
      const bool limited = std::isfinite(spec.lower) || std::isfinite(spec.upper);
      slider->setLowerLinLimit(limited ? spec.lower : 1.0);  // (lower above upper: free)
      slider->setUpperLinLimit(limited ? spec.upper : -1.0);
      slider->setLowerAngLimit(0.0);
      slider->setUpperAngLimit(0.0);
      joint.constraint = std::move(slider);
      break;
    }
    case JointSpec::Kind::Ball:
      joint.constraint =
          std::make_unique<btPoint2PointConstraint>(child, parent, in_child.getOrigin(), in_parent.getOrigin());
      break;
    case JointSpec::Kind::Fixed:
      joint.constraint = std::make_unique<btFixedConstraint>(child, parent, in_child, in_parent);
      break;
    case JointSpec::Kind::Rigid:
      break;
  }
}

void BulletEngine::removeJoint(int index) {
  const auto k = static_cast<std::size_t>(index);
  if (!sealed_ || index < 0 || k < scene_joints_ || k >= joints_.size() || joints_[k].removed)
    throw Error("bullet: joint " + std::to_string(index) + " is not a run-time joint in place (only those can be removed)");
  joints_[k].constraint.reset();
  joints_[k].removed = true;
  --live_joints_;
  labels_stale_ = true;
}

void BulletEngine::saveJoints(StateWriter& out) const {
  // the run-time joints, each with its frames in both bodies
  saveRunTimeJoints(out, joints_, sealed_ ? scene_joints_ : joints_.size(), [](StateWriter& w, const Joint& j) {
    w.bytes(j.in_child, sizeof j.in_child);
    w.bytes(j.in_parent, sizeof j.in_parent);
  });
}

std::vector<BulletEngine::Joint> BulletEngine::loadJoints(StateReader& in) const {
  return loadRunTimeJoints<Joint>(in, static_cast<int>(bodies_.size()), "bullet", [](StateReader& r, Joint& j) {
    r.bytes(j.in_child, sizeof j.in_child);
    r.bytes(j.in_parent, sizeof j.in_parent);
    bool finite = true;
    for (const double v : j.in_child) finite = finite && std::isfinite(v);
    for (const double v : j.in_parent) finite = finite && std::isfinite(v);
    return finite;
  });
}

void BulletEngine::setJointMotor(int index, double velocity, double max_effort) {
  Joint& joint = joints_.at(static_cast<std::size_t>(index));
  if (joint.removed) throw Error("bullet: joint " + std::to_string(index) + " was removed");
  joint.velocity = velocity;
  joint.max_effort = max_effort;
}

void BulletEngine::setMotors(double h) {
  // Bullet's hinge takes the motor's limit as an impulse per substep, its slider as a force
  for (Joint& j : joints_) {
    if (j.removed) continue;
    const bool on = j.max_effort > 0;
    if (j.spec.kind == JointSpec::Kind::Hinge)
      static_cast<btHingeConstraint&>(*j.constraint).enableAngularMotor(on, j.velocity, j.max_effort * h);
    if (j.spec.kind == JointSpec::Kind::Slider) {
      auto& slider = static_cast<btSliderConstraint&>(*j.constraint);
      slider.setPoweredLinMotor(on);
      slider.setTargetLinMotorVelocity(j.velocity);
      slider.setMaxLinMotorForce(j.max_effort);
    }
  }
}

}  // namespace ssx::detail
