// The Bullet engine's joints: Bullet's hinge, slider, point-to-point and fixed constraints, their
// limits and motors (solved with the island of their bodies: bullet_contacts.cpp).
#include "bullet/bullet_parts.hpp"

#include <ssx/error.hpp>

#include <cmath>
#include <numbers>

namespace ssx::detail {

using namespace bullet;

namespace {

btTransform toBt(const Pose& p) { return btTransform(bullet::toBt(p.orientation.normalized()), bullet::toBt(p.position)); }

}  // namespace

int BulletEngine::addJoint(const EngineJoint& spec) {
  const auto count = static_cast<int>(bodies_.size());
  if (spec.child < 0 || spec.child >= count || spec.parent >= count || spec.parent == spec.child ||
      spec.kind == JointSpec::Kind::Rigid)
    throw Error("bullet: a joint needs a kind and two different bodies (or a body and the world)");
  btRigidBody& child = *bodies_[static_cast<std::size_t>(spec.child)]->rb;
  btRigidBody& parent =
      spec.parent >= 0 ? *bodies_[static_cast<std::size_t>(spec.parent)]->rb : btTypedConstraint::getFixedBody();
  // the joint's frame in each body (Bullet's body frame: the centre of mass on principal axes);
  // the static world's body is at the origin
  const btTransform frame = toBt(spec.frame);
  const btTransform in_child = child.getCenterOfMassTransform().inverse() * frame;
  const btTransform in_parent = spec.parent >= 0 ? parent.getCenterOfMassTransform().inverse() * frame : frame;
  Joint joint;
  joint.spec = spec;
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
  if (spec.parent >= 0) {
    const int keep = std::min(articulation_[static_cast<std::size_t>(spec.child)],
                              articulation_[static_cast<std::size_t>(spec.parent)]);
    const int drop = std::max(articulation_[static_cast<std::size_t>(spec.child)],
                              articulation_[static_cast<std::size_t>(spec.parent)]);
    for (int& a : articulation_)
      if (a == drop) a = keep;
  }
  joints_.push_back(std::move(joint));
  proxies_stale_ = true;
  return static_cast<int>(joints_.size() - 1);
}

void BulletEngine::setJointMotor(int index, double velocity, double max_effort) {
  Joint& joint = joints_.at(static_cast<std::size_t>(index));
  joint.velocity = velocity;
  joint.max_effort = max_effort;
}

void BulletEngine::setMotors(double h) {
  // Bullet's hinge takes the motor's limit as an impulse per substep, its slider as a force
  for (Joint& j : joints_) {
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
