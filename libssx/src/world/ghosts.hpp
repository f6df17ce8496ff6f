#pragma once
// Ghosts: artifacts whose pose comes from outside (a real robot's motion capture), kinematic in the
// physics. Each has a PoseStream; every step the body is moved from the pose at the step's start to
// the pose the stream gives for its end (the engine sees that velocity in its contacts), then put
// exactly on it. A ghost with no pose yet, or none for longer than its timeout, is lost: it holds
// where it was, its sensors do not measure, and the log says so.

#include <ssx/pose_stream.hpp>

#include <cstdint>
#include <vector>

namespace ssx {
class Environment;
class PhysicEngine;
}  // namespace ssx

namespace ssx::detail {

struct World;

class Ghosts {
 public:
  struct Ghost {
    std::uint32_t artifact = 0;
    int body = -1;                    // from start
    Pose root_in_body;                // the root node's frame in the body's frame
    PoseStream stream;
    bool lost = true;                 // no pose yet, or too old
    bool tracked = false;             // had a pose once (for the log only)
  };

  bool empty() const noexcept { return ghosts_.empty(); }
  // setup: one ghost per artifact
  void add(std::uint32_t artifact, const PoseStream::Settings& settings);
  Ghost* find(std::uint32_t artifact);
  const Ghost* find(std::uint32_t artifact) const;
  const std::vector<Ghost>& list() const noexcept { return ghosts_; }

  // start: the bodies made kinematic and placed where their streams say at time 0
  void start(World& world, PhysicEngine& engine);
  // makes the ghosts' bodies kinematic in another engine (switching engines)
  void adopt(PhysicEngine& engine) const;
  // around the physics step that ends at `t_next`: the velocity that takes each body there, and
  // the exact pose there afterwards (before the snapshot is read)
  void beforePhysics(World& world, PhysicEngine& engine, double t_next, double dt);
  void afterPhysics(World& world, PhysicEngine& engine, double t_next, const Environment& env);

  // the streams and lost flags (the ages are a diagnostic, not state)
  void save(StateWriter& out) const;
  void load(StateReader& in, World& world);
  AgeSummary ages() const { return ages_.summary(); }

 private:
  void setLost(Ghost& g, bool lost, World& world, const Environment& env, double t);
  std::vector<Ghost> ghosts_;  // by artifact index
  AgeHistogram ages_;
};

}  // namespace ssx::detail
