// Joints made and broken at run time (PhysicNode::attach, release, detach): a gripper closing on
// an object, an object let go. Asked for during a step by an artifact's own driver, they are
// carried out when the drivers phase ends, artifact by artifact in the order asked (so the outcome
// does not depend on the thread count), at the poses the drivers saw: before an extension's
// afterStep or the program could move a body; asked for between steps, at once.
#include "world/phase_guard.hpp"
#include "world/phases.hpp"
#include "world/world.hpp"

#include <ssx/environment.hpp>
#include <ssx/physic_node.hpp>

#include <algorithm>

namespace ssx {

namespace detail {

namespace {

int bodyOf(const World& world, std::uint32_t node) { return world.nodes[node].body; }

void count(World& world, const Attachment& a, int delta) {
  for (const int b : {bodyOf(world, a.holder), bodyOf(world, a.held)})
    if (b >= 0) world.attached[static_cast<std::size_t>(b)] = static_cast<std::uint16_t>(world.attached[static_cast<std::size_t>(b)] + delta);
}

void attach(World& world, PhysicEngine& engine, std::uint32_t holder, std::uint32_t held, JointSpec::Kind kind) {
  const int a = bodyOf(world, holder), b = bodyOf(world, held);
  // a pair already joined at run time stays as it is
  for (const Attachment& x : world.attachments) {
    const int xa = bodyOf(world, x.holder), xb = bodyOf(world, x.held);
    if ((xa == a && xb == b) || (xa == b && xb == a)) return;
  }
  EngineJoint joint;
  joint.kind = kind;
  joint.run_time = true;
  // held fixed in the holder's body where it is now (a static node: the holder fixed in the world);
  // a ball joint's anchor is the holder node's origin
  joint.parent = b >= 0 ? a : -1;
  joint.child = b >= 0 ? b : a;
  joint.frame = kind == JointSpec::Kind::Ball ? world.node_handles[holder].pose()
                                              : world.states[static_cast<std::size_t>(joint.child)].pose;
  Attachment x{holder, held, engine.addJoint(joint), kind};
  count(world, x, 1);
  world.attachments.push_back(x);
}

template <class Match>
void remove(World& world, PhysicEngine& engine, Match&& match) {
  std::size_t kept = 0;
  for (const Attachment& x : world.attachments) {
    if (!match(x)) {
      world.attachments[kept++] = x;
      continue;
    }
    engine.removeJoint(x.engine);
    count(world, x, -1);
  }
  world.attachments.resize(kept);
}

void carryOut(World& world, PhysicEngine& engine, const AttachRequest& r) {
  switch (r.kind) {
    case AttachRequest::Kind::Attach:
      attach(world, engine, r.node, r.other, r.joint);
      break;
    case AttachRequest::Kind::Release:
      remove(world, engine, [&](const Attachment& x) { return x.holder == r.node; });
      break;
    case AttachRequest::Kind::Detach: {
      const int body = bodyOf(world, r.node);
      remove(world, engine, [&](const Attachment& x) {
        return bodyOf(world, x.holder) == body || bodyOf(world, x.held) == body;
      });
      break;
    }
  }
}

// asked for now: at once between steps, else queued for the next step's physics
void request(World& world, const AttachRequest& r) {
  if (!PhaseGuard::now.in_phase) {
    carryOut(world, *world.engine, r);
    return;
  }
  world.artifact_data[world.node_handles[r.node].artifact().index()].attach_requests.push_back(r);
  world.attach_pending.store(true, std::memory_order_relaxed);
}

}  // namespace

void applyAttachRequests(World& world, PhysicEngine& engine) {
  world.attach_pending.store(false, std::memory_order_relaxed);
  for (ArtifactData& a : world.artifact_data) {
    for (const AttachRequest& r : a.attach_requests) carryOut(world, engine, r);
    a.attach_requests.clear();
  }
}

void reattach(World& world, PhysicEngine& engine) {
  // held where they are now: the same relative poses as when they were made (joints keep them)
  std::vector<Attachment> made = std::move(world.attachments);
  world.attachments.clear();
  std::fill(world.attached.begin(), world.attached.end(), std::uint16_t{0});
  for (const Attachment& x : made) attach(world, engine, x.holder, x.held, x.kind);
}

void loadAttachments(World& world, StateReader& in) {
  const auto nodes = world.nodes.size();
  auto bad = [] { return StateError("saved state: a run-time joint (attach) does not fit this world (corrupted)"); };
  std::vector<Attachment> attachments(in.count(13));
  for (Attachment& x : attachments) {
    in.read(x.holder);
    in.read(x.held);
    x.engine = in.get<std::int32_t>();
    const auto kind = in.get<std::uint8_t>();
    if (x.holder >= nodes || x.held >= nodes || x.engine < 0 || world.nodes[x.holder].body < 0) throw bad();
    if (kind != static_cast<std::uint8_t>(JointSpec::Kind::Fixed) && kind != static_cast<std::uint8_t>(JointSpec::Kind::Ball))
      throw bad();
    x.kind = static_cast<JointSpec::Kind>(kind);
  }
  world.attachments = std::move(attachments);
  std::fill(world.attached.begin(), world.attached.end(), std::uint16_t{0});
  for (const Attachment& x : world.attachments) count(world, x, 1);
}

}  // namespace detail

namespace {

std::string who(const PhysicNode& n) { return "artifact '" + n.artifact().name() + "', node '" + n.name() + "'"; }

}  // namespace

void PhysicNode::attach(const PhysicNode& other, JointSpec::Kind joint) {
  requireWritable();
  if (world_->engine == nullptr || !world_->started()) throw Error(who(*this) + ": attach once the environment has started");
  if (other.world_ != world_) throw Error(who(*this) + ": attach: '" + other.name() + "' is of another environment");
  const int a = bodyIndex(), b = other.bodyIndex();
  if (a < 0) throw Error(who(*this) + ": a static node cannot hold anything (attach the other way round)");
  if (a == b) throw Error(who(*this) + ": attach: '" + other.name() + "' is part of the same body");
  if (joint != JointSpec::Kind::Fixed && joint != JointSpec::Kind::Ball)
    throw Error(who(*this) + ": attach holds by a fixed or a ball joint");
  for (const int body : {a, b})
    if (body >= 0 && world_->engine->isKinematic(body))
      throw Error(who(*this) + ": attach: a ghost (a kinematic body) cannot hold or be held");
  detail::request(*world_, {detail::AttachRequest::Kind::Attach, static_cast<std::uint32_t>(index_),
                            static_cast<std::uint32_t>(other.index_), joint});
}

void PhysicNode::release() {
  requireWritable();
  if (!world_->started()) throw Error(who(*this) + ": release once the environment has started");
  detail::request(*world_, {detail::AttachRequest::Kind::Release, static_cast<std::uint32_t>(index_), 0});
}

void PhysicNode::detach() {
  requireWritable();
  if (!world_->started()) throw Error(who(*this) + ": detach once the environment has started");
  detail::request(*world_, {detail::AttachRequest::Kind::Detach, static_cast<std::uint32_t>(index_), 0});
}

std::size_t PhysicNode::attachments() const noexcept {
  const int b = bodyIndex();
  return b < 0 || world_->attached.empty() ? 0 : world_->attached[static_cast<std::size_t>(b)];
}

}  // namespace ssx
