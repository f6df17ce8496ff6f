// The ODE engine's joints: hinge, slider, ball and fixed joints between bodies pinned to world 0
// (see ode_engine.hpp), their limits and motors; joints made and removed between steps, saved.
#include "engines/ode/ode_engine.hpp"

#include "engines/articulations.hpp"

#include <ssx/error.hpp>

#include <algorithm>
#include <cmath>

namespace ssx::detail {

int OdeEngine::addJoint(const EngineJoint& spec) {
  ensureThreadData();
  const auto bodies = static_cast<int>(bodies_.size());
  if (spec.child < 0 || spec.child >= bodies || spec.parent >= bodies || spec.parent == spec.child ||
      spec.kind == JointSpec::Kind::Rigid)
    throw Error("ode: a joint needs a kind and two different bodies (or a body and the world)");
  if (spec.run_time)
    seal();
  else if (sealed_)
    throw Error("ode: the scene's joints come before any step and any run-time joint");
  Joint joint;
  joint.spec = spec;
  // both bodies in world 0 for good (see ode_engine.hpp), before ODE joins them there
  for (const int b : {spec.child, spec.parent}) {
    if (b < 0) continue;
    Body& body = bodies_[static_cast<std::size_t>(b)];
    body.pinned = true;
    body.home = 0;
    if (body.partition != 0) moveBody(b, 0);
  }
  joint.child_bits.resize(kOdeBodyReals);
  readOdeBits(bodies_[static_cast<std::size_t>(spec.child)].id, joint.child_bits.data());
  if (spec.parent >= 0) {
    joint.parent_bits.resize(kOdeBodyReals);
    readOdeBits(bodies_[static_cast<std::size_t>(spec.parent)].id, joint.parent_bits.data());
  }
  createJoint(joint);
  // a run-time joint takes the first slot one let go of
  const std::size_t slot = placeJoint(joints_, std::move(joint), scene_joints_, sealed_);
  ++live_joints_;
  labels_stale_ = true;
  return static_cast<int>(slot);
}

void OdeEngine::removeJoint(int index) {
  const auto k = static_cast<std::size_t>(index);
  if (!sealed_ || index < 0 || k < scene_joints_ || k >= joints_.size() || joints_[k].removed)
    throw Error("ode: joint " + std::to_string(index) + " is not a run-time joint in place (only those can be removed)");
  dJointDestroy(joints_[k].id);
  joints_[k].id = nullptr;
  joints_[k].removed = true;
  --live_joints_;
  repin(true);
  labels_stale_ = true;
}

void OdeEngine::repin(bool move) {
  std::vector<char> held(bodies_.size(), 0);
  for (const Joint& j : joints_) {
    if (j.removed) continue;
    held[static_cast<std::size_t>(j.spec.child)] = 1;
    if (j.spec.parent >= 0) held[static_cast<std::size_t>(j.spec.parent)] = 1;
  }
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    Body& body = bodies_[i];
    body.pinned = held[i] != 0;
    body.home = body.pinned ? 0 : homeOf(static_cast<int>(i));
    if (!move) continue;
    if (body.pinned && body.partition != 0) moveBody(static_cast<int>(i), 0);
    // let go: home at the next step unless a contact group keeps it (as groupContacts does)
    if (!body.pinned && body.partition != body.home && std::find(away_.begin(), away_.end(), static_cast<int>(i)) == away_.end())
      away_.push_back(static_cast<int>(i));
  }
}

namespace {

// ODE's hinge and slider take the same parameters (stops, motor), each through its own setter;
// other joints have none
void setAxisParam(JointSpec::Kind kind, dJointID j, int param, double value) {
  if (kind == JointSpec::Kind::Hinge) dJointSetHingeParam(j, param, value);
  if (kind == JointSpec::Kind::Slider) dJointSetSliderParam(j, param, value);
}

}  // namespace

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
      break;
    case JointSpec::Kind::Slider:
      j = dJointCreateSlider(world, nullptr);
      dJointAttach(j, child, parent);
      dJointSetSliderAxis(j, z.x(), z.y(), z.z());
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
  if (std::isfinite(s.lower)) setAxisParam(s.kind, j, dParamLoStop, s.lower);
  if (std::isfinite(s.upper)) setAxisParam(s.kind, j, dParamHiStop, s.upper);
  joint.id = j;
}

void OdeEngine::recreateJoints() {
  // each joint's bodies where they were when it was first made, so that ODE takes the same frames;
  // the caller then writes every body's saved state
  for (Joint& joint : joints_) {
    if (joint.removed) continue;
    writeOdeBits(bodies_[static_cast<std::size_t>(joint.spec.child)].id, joint.child_bits.data());
    if (joint.spec.parent >= 0)
      writeOdeBits(bodies_[static_cast<std::size_t>(joint.spec.parent)].id, joint.parent_bits.data());
    createJoint(joint);
    applyMotor(joint);
  }
}

void OdeEngine::setJointMotor(int index, double velocity, double max_effort) {
  Joint& joint = joints_.at(static_cast<std::size_t>(index));
  if (joint.removed) throw Error("ode: joint " + std::to_string(index) + " was removed");
  joint.velocity = velocity;
  joint.max_effort = max_effort;
  applyMotor(joint);
}

void OdeEngine::applyMotor(const Joint& joint) {
  setAxisParam(joint.spec.kind, joint.id, dParamVel, joint.velocity);
  setAxisParam(joint.spec.kind, joint.id, dParamFMax, joint.max_effort);
}

void OdeEngine::saveJoints(StateWriter& out) const {
  // the run-time joints, each with what makes it again to the bit: its bodies' states when made
  saveRunTimeJoints(out, joints_, sealed_ ? scene_joints_ : joints_.size(), [](StateWriter& w, const Joint& j) {
    w.bytes(j.child_bits.data(), j.child_bits.size() * sizeof(dReal));
    if (j.spec.parent >= 0) w.bytes(j.parent_bits.data(), j.parent_bits.size() * sizeof(dReal));
  });
}

std::vector<OdeEngine::Joint> OdeEngine::loadJoints(StateReader& in) const {
  return loadRunTimeJoints<Joint>(in, static_cast<int>(bodies_.size()), "ode", [](StateReader& r, Joint& j) {
    bool finite = true;
    for (auto* bits : {&j.child_bits, &j.parent_bits}) {
      if (bits == &j.parent_bits && j.spec.parent < 0) break;
      bits->resize(kOdeBodyReals);
      r.bytes(bits->data(), kOdeBodyReals * sizeof(dReal));
      for (const dReal v : *bits) finite = finite && std::isfinite(v);
    }
    return finite;
  });
}

}  // namespace ssx::detail
