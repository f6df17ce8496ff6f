// The ODE engine's joints: hinge, slider, ball and fixed joints between pinned bodies, each
// articulation in one world (see ode_engine.hpp), their limits and motors; joints made and removed
// between steps, saved.
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
  for (const int b : {spec.child, spec.parent})
    if (b >= 0) bodies_[static_cast<std::size_t>(b)].pinned = true;
  if (!sealed_) {
    // the scene's joints in world 0 (cheap while the scene is built); each articulation goes home
    // at the first step (groupContacts)
    for (const int b : {spec.child, spec.parent})
      if (b >= 0 && bodies_[static_cast<std::size_t>(b)].partition != 0) moveBody(b, 0);
  } else if (spec.parent >= 0) {
    // a joint between steps: both articulations in the world of the lower one, before ODE joins them
    if (labels_stale_ || articulation_.size() != bodies_.size()) refreshLabels(false);
    const int a = articulation_[static_cast<std::size_t>(spec.child)];
    const int b = articulation_[static_cast<std::size_t>(spec.parent)];
    const int to = bodies_[static_cast<std::size_t>(std::min(a, b))].partition;
    relocate(std::max(a, b), to);
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

void OdeEngine::repin(bool list_away) {
  std::vector<char> held(bodies_.size(), 0);
  for (const Joint& j : joints_) {
    if (j.removed) continue;
    held[static_cast<std::size_t>(j.spec.child)] = 1;
    if (j.spec.parent >= 0) held[static_cast<std::size_t>(j.spec.parent)] = 1;
  }
  for (std::size_t i = 0; i < bodies_.size(); ++i) bodies_[i].pinned = held[i] != 0;
  refreshLabels(list_away);
}

void OdeEngine::refreshLabels(bool list_away) {
  labelArticulations(articulation_, bodies_.size(), joints_);
  labelStaticParents(hangs_from_, articulation_, joints_);
  labels_stale_ = false;
  // each articulation's bodies and joints, by its root (a counting sort: ascending, slot order)
  const std::size_t n = bodies_.size();
  member_offset_.assign(n + 1, 0);
  joint_offset_.assign(n + 1, 0);
  for (const int r : articulation_) ++member_offset_[static_cast<std::size_t>(r) + 1];
  for (const Joint& j : joints_)
    if (!j.removed)
      ++joint_offset_[static_cast<std::size_t>(articulation_[static_cast<std::size_t>(j.spec.child)]) + 1];
  for (std::size_t r = 0; r < n; ++r) {
    member_offset_[r + 1] += member_offset_[r];
    joint_offset_[r + 1] += joint_offset_[r];
  }
  members_.resize(n);
  art_joints_.resize(static_cast<std::size_t>(joint_offset_[n]));
  std::vector<int> fill(member_offset_.begin(), member_offset_.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    members_[static_cast<std::size_t>(fill[static_cast<std::size_t>(articulation_[i])]++)] = static_cast<int>(i);
  fill.assign(joint_offset_.begin(), joint_offset_.end() - 1);
  for (std::size_t k = 0; k < joints_.size(); ++k) {
    if (joints_[k].removed) continue;
    const auto r = static_cast<std::size_t>(articulation_[static_cast<std::size_t>(joints_[k].spec.child)]);
    art_joints_[static_cast<std::size_t>(fill[r]++)] = static_cast<int>(k);
  }
  // a pinned body's home is its articulation's; a body away goes home when no group needs it
  for (std::size_t i = 0; i < n; ++i) {
    Body& body = bodies_[i];
    body.home = homeOf(body.pinned ? articulation_[i] : static_cast<int>(i));
    if (list_away && body.partition != body.home) listAway(static_cast<int>(i));
  }
}

void OdeEngine::listAway(int i) {
  Body& body = bodies_[static_cast<std::size_t>(i)];
  if (body.listed) return;
  body.listed = true;
  away_.push_back(i);
}

void OdeEngine::relocate(int root, int to) {
  const std::span<const int> members = membersOf(root);
  bool there = true;
  for (const int i : members) there = there && bodies_[static_cast<std::size_t>(i)].partition == to;
  if (there) return;
  const std::span<const int> joints = jointsOf(root);
  // (an ODE joint cannot follow its bodies: it is let go of here and made again there)
  for (const int k : joints) {
    dJointDestroy(joints_[static_cast<std::size_t>(k)].id);
    joints_[static_cast<std::size_t>(k)].id = nullptr;
  }
  for (const int i : members) {
    Body& body = bodies_[static_cast<std::size_t>(i)];
    if (body.partition == to) continue;
    if (to != body.home) listAway(i);
    moveBody(i, to);
  }
  remakeJoints(joints);
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
  const dWorldID world =
      partitions_[static_cast<std::size_t>(bodies_[static_cast<std::size_t>(s.child)].partition)].world;
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

void OdeEngine::remakeJoints(std::span<const int> joints) {
  // where the bodies are now, then each joint made from its bodies' states when first made
  std::vector<int> held;
  for (const int k : joints)
    for (const int b :
         {joints_[static_cast<std::size_t>(k)].spec.child, joints_[static_cast<std::size_t>(k)].spec.parent})
      if (b >= 0) held.push_back(b);
  std::sort(held.begin(), held.end());
  held.erase(std::unique(held.begin(), held.end()), held.end());
  std::vector<dReal> now(held.size() * kOdeBodyReals);
  for (std::size_t h = 0; h < held.size(); ++h)
    readOdeBits(bodies_[static_cast<std::size_t>(held[h])].id, now.data() + h * kOdeBodyReals);
  for (const int k : joints) {
    Joint& joint = joints_[static_cast<std::size_t>(k)];
    writeOdeBits(bodies_[static_cast<std::size_t>(joint.spec.child)].id, joint.child_bits.data());
    if (joint.spec.parent >= 0)
      writeOdeBits(bodies_[static_cast<std::size_t>(joint.spec.parent)].id, joint.parent_bits.data());
    createJoint(joint);
    applyMotor(joint);
  }
  for (std::size_t h = 0; h < held.size(); ++h)
    writeOdeBits(bodies_[static_cast<std::size_t>(held[h])].id, now.data() + h * kOdeBodyReals);
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

void OdeEngine::checkJointWorlds(const std::vector<Joint>& run_time, const std::vector<int>& where) const {
  for (std::size_t k = 0; k < scene_joints_ + run_time.size(); ++k) {
    const Joint& j = k < scene_joints_ ? joints_[k] : run_time[k - scene_joints_];
    if (!j.removed && j.spec.parent >= 0 &&
        where[static_cast<std::size_t>(j.spec.child)] != where[static_cast<std::size_t>(j.spec.parent)])
      throw StateError("ode: the saved state puts the two bodies of joint " + std::to_string(k) +
                       " in different worlds");
  }
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
