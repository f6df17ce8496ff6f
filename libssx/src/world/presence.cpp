// Artifacts out of the world and back (Environment::despawn and spawn): the world's arrays keep
// every artifact, its bodies and its plugins whatever happens, so that indices, streams, saved
// states and the threads' shares never change; an artifact out of the world has its bodies taken
// out of the physics engine (PhysicEngine::setEnabled), its driver and sensors skipped by the
// phases and its root left out of the neighbour index.
#include "world/ghosts.hpp"
#include "world/neighbor_index.hpp"
#include "world/phases.hpp"
#include "world/world.hpp"

#include <ssx/environment.hpp>
#include <ssx/error.hpp>

#include <cmath>
#include <string>

namespace ssx {

namespace detail {

void applyPresence(World& world, PhysicEngine& engine, std::span<const std::uint8_t> was_absent) {
  for (std::size_t i = 0; i < world.artifact_data.size(); ++i) {
    const ArtifactData& a = world.artifact_data[i];
    const bool before = was_absent.empty() ? false : was_absent[i] != 0;
    if (a.absent == before) continue;
    for (int b = a.body_begin; b < a.body_end; ++b) engine.setEnabled(b, !a.absent);
  }
}

}  // namespace detail

bool Artifact::present() const noexcept { return !world_->artifact_data[index_].absent; }

void Environment::checkPresenceChange(const Artifact& artifact, const char* what) const {
  requireOutsidePhases(what);
  const detail::World& w = *world_;
  if (artifact.index() >= w.artifacts.size() || w.artifacts[artifact.index()].get() != &artifact)
    throw Error(std::string(what) + ": artifact '" + artifact.name() + "' belongs to another environment");
  if (w.configuring) throw Error(std::string(what) + " is not allowed from configure: call it between steps");
  if (w.state == State::Stopped || w.state == State::Failed)
    throw Error(std::string(what) + ": the environment " + (w.state == State::Failed ? "failed" : "was stopped"));
  const std::string who = "'" + artifact.name() + "'";
  if (artifact.rootCount() == 0 || artifact.root().isStatic())
    throw Error(std::string(what) + ": " + who +
                " is fixed in the world (static shapes stay where the scene put them)");
  if (isGhost(artifact)) throw Error(std::string(what) + ": " + who + " is a ghost: its pose comes from outside");
}

void Environment::despawn(Artifact& artifact) {
  checkPresenceChange(artifact, "despawn");
  detail::World& w = *world_;
  detail::ArtifactData& a = w.data(artifact);
  if (a.absent) throw Error("despawn: '" + artifact.name() + "' is out of the world already");
  if (w.state == State::Setup) {
    a.absent = true;  // it starts out of the world (start takes its bodies out)
    return;
  }
  for (int b = a.body_begin; b < a.body_end; ++b)
    if (!w.attached.empty() && w.attached[static_cast<std::size_t>(b)] > 0)
      throw Error("despawn: '" + artifact.name() +
                  "' holds or is held by another artifact (PhysicNode::attach): release it first");
  a.absent = true;
  for (int b = a.body_begin; b < a.body_end; ++b) {
    const auto k = static_cast<std::size_t>(b);
    physics_->setEnabled(b, false);
    w.wrenches[k] = Wrench{};  // (its driver no longer runs to clear them)
  }
  rays_stale_ = true;
  if (neighbors_->enabled()) neighbors_->markMembersChanged(w);
}

void Environment::spawn(Artifact& artifact, const Pose& pose) {
  checkPresenceChange(artifact, "spawn");
  detail::World& w = *world_;
  if (w.state != State::Running)
    throw Error("spawn: the environment is not running (before start an artifact starts where the scene places it)");
  detail::ArtifactData& a = w.data(artifact);
  if (!a.absent) throw Error("spawn: '" + artifact.name() + "' is in the world already (despawn takes it out)");
  const Quat& q = pose.orientation;
  if (!pose.position.allFinite() || !q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-3)
    throw Error("spawn: the pose for '" + artifact.name() + "' is not finite or its quaternion is not of unit length");
  // every body moved rigidly with its root frame, at rest
  const Pose target{pose.position, q.normalized()};
  const Pose motion = target * artifact.root().pose().inverse();
  for (int b = a.body_begin; b < a.body_end; ++b) {
    const auto k = static_cast<std::size_t>(b);
    BodyState& s = w.states[k];
    s.pose = motion * s.pose;
    s.pose.orientation.normalize();
    s.linear_velocity = s.angular_velocity = Vec3::Zero();
    s.linear_acceleration = s.angular_acceleration = Vec3::Zero();
    w.previous_linear[k] = w.previous_angular[k] = Vec3::Zero();
    w.wrenches[k] = Wrench{};
    physics_->setState(b, s);
    physics_->setEnabled(b, true);
  }
  a.absent = false;
  rays_stale_ = true;
  if (neighbors_->enabled()) neighbors_->markMembersChanged(w);
}

}  // namespace ssx
