// The ODE engine's joints: hinge, slider, ball and fixed joints between bodies pinned to world 0
// (see ode_engine.hpp), their limits and motors.
#include "ode/ode_engine.hpp"

#include <ssx/error.hpp>

#include <cmath>

namespace ssx::detail {

int OdeEngine::addJoint(const EngineJoint& spec) {
  ensureThreadData();
  const auto bodies = static_cast<int>(bodies_.size());
  if (spec.child < 0 || spec.child >= bodies || spec.parent >= bodies || spec.parent == spec.child ||
      spec.kind == JointSpec::Kind::Rigid)
    throw Error("ode: a joint needs a kind and two different bodies (or a body and the world)");
  // both bodies in world 0 for good (see ode_engine.hpp)
  for (const int b : {spec.child, spec.parent}) {
    if (b < 0) continue;
    Body& body = bodies_[static_cast<std::size_t>(b)];
    body.pinned = true;
    body.home = 0;
    if (body.partition != 0) moveBody(b, 0);
  }
  // one articulation: the lower label wins
  if (spec.parent >= 0) {
    const int keep = std::min(articulation_[static_cast<std::size_t>(spec.child)],
                              articulation_[static_cast<std::size_t>(spec.parent)]);
    const int drop = std::max(articulation_[static_cast<std::size_t>(spec.child)],
                              articulation_[static_cast<std::size_t>(spec.parent)]);
    for (int& a : articulation_)
      if (a == drop) a = keep;
  }
  Joint joint;
  joint.spec = spec;
  joint.child_bits.resize(kOdeBodyReals);
  readOdeBits(bodies_[static_cast<std::size_t>(spec.child)].id, joint.child_bits.data());
  if (spec.parent >= 0) {
    joint.parent_bits.resize(kOdeBodyReals);
    readOdeBits(bodies_[static_cast<std::size_t>(spec.parent)].id, joint.parent_bits.data());
  }
  createJoint(joint);
  joints_.push_back(std::move(joint));
  proxies_stale_ = true;
  return static_cast<int>(joints_.size() - 1);
}

void OdeEngine::createJoint(Joint& joint) {
  const EngineJoint& s = joint.spec;
  const dWorldID world = partitions_[0].world;
  // the child is ODE's first body, so that ODE's angle, rate and motor are the child's relative to
  // the parent, as ssx measures them
  const dBodyID child = bodies_[static_cast<std::size_t>(s.child)].id;
  const dBodyID parent = s.parent >= 0 ? bodies_[static_cast<std::size_t>(s.parent)].id : nullptr;
  const Vec3& o = s.frame.position;
  const Vec3 z = s.frame.orientation * Vec3::UnitZ();
  dJointID j = nullptr;
  switch (s.kind) {
    case JointSpec::Kind::Hinge:
      j = dJointCreateHinge(world, nullptr);
      dJointAttach(j, child, parent);
      dJointSetHingeAnchor(j, o.x(), o.y(), o.z());
      dJointSetHingeAxis(j, z.x(), z.y(), z.z());
      if (std::isfinite(s.lower)) dJointSetHingeParam(j, dParamLoStop, s.lower);
      if (std::isfinite(s.upper)) dJointSetHingeParam(j, dParamHiStop, s.upper);
      break;
    case JointSpec::Kind::Slider:
      j = dJointCreateSlider(world, nullptr);
      dJointAttach(j, child, parent);
      dJointSetSliderAxis(j, z.x(), z.y(), z.z());
      if (std::isfinite(s.lower)) dJointSetSliderParam(j, dParamLoStop, s.lower);
      if (std::isfinite(s.upper)) dJointSetSliderParam(j, dParamHiStop, s.upper);
      break;
    case JointSpec::Kind::Ball:
      j = dJointCreateBall(world, nullptr);
      dJointAttach(j, child, parent);
      dJointSetBallAnchor(j, o.x(), o.y(), o.z());
      break;
    case JointSpec::Kind::Fixed:
      j = dJointCreateFixed(world, nullptr);
      dJointAttach(j, child, parent);
      dJointSetFixed(j);
      break;
    case JointSpec::Kind::Rigid:
      break;
  }
  joint.id = j;
}

void OdeEngine::recreateJoints() {
  // each joint's bodies where they were when it was first made, so that ODE takes the same frames;
  // the caller then writes every body's saved state
  for (Joint& joint : joints_) {
    writeOdeBits(bodies_[static_cast<std::size_t>(joint.spec.child)].id, joint.child_bits.data());
    if (joint.spec.parent >= 0)
      writeOdeBits(bodies_[static_cast<std::size_t>(joint.spec.parent)].id, joint.parent_bits.data());
    createJoint(joint);
    applyMotor(joint);
  }
}

void OdeEngine::setJointMotor(int index, double velocity, double max_effort) {
  Joint& joint = joints_.at(static_cast<std::size_t>(index));
  joint.velocity = velocity;
  joint.max_effort = max_effort;
  applyMotor(joint);
}

void OdeEngine::applyMotor(const Joint& joint) {
  if (joint.spec.kind == JointSpec::Kind::Hinge) {
    dJointSetHingeParam(joint.id, dParamVel, joint.velocity);
    dJointSetHingeParam(joint.id, dParamFMax, joint.max_effort);
  }
  if (joint.spec.kind == JointSpec::Kind::Slider) {
    dJointSetSliderParam(joint.id, dParamVel, joint.velocity);
    dJointSetSliderParam(joint.id, dParamFMax, joint.max_effort);
  }
}

}  // namespace ssx::detail
