#include "world/ghosts.hpp"

#include "world/world.hpp"

#include <ssx/environment.hpp>
#include <ssx/physic_engine.hpp>

#include <algorithm>
#include <cstdio>

namespace ssx::detail {

namespace {

// the body's state for a pose and velocities of its artifact's root frame
BodyState bodyState(const PoseStream::Estimate& e, const Pose& root_in_body) {
  BodyState s;
  s.pose = e.pose * root_in_body.inverse();
  s.angular_velocity = e.angular_velocity;
  s.linear_velocity = e.linear_velocity + e.angular_velocity.cross(s.pose.position - e.pose.position);
  return s;
}

std::string seconds(double t) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", t);
  return text;
}

}  // namespace

void Ghosts::add(std::uint32_t artifact, const PoseStream::Settings& settings) {
  Ghost g;
  g.artifact = artifact;
  g.stream = PoseStream(settings);
  const auto at = std::lower_bound(ghosts_.begin(), ghosts_.end(), artifact,
                                   [](const Ghost& x, std::uint32_t a) { return x.artifact < a; });
  ghosts_.insert(at, std::move(g));
}

Ghosts::Ghost* Ghosts::find(std::uint32_t artifact) {
  const auto at = std::lower_bound(ghosts_.begin(), ghosts_.end(), artifact,
                                   [](const Ghost& x, std::uint32_t a) { return x.artifact < a; });
  return at != ghosts_.end() && at->artifact == artifact ? &*at : nullptr;
}

const Ghosts::Ghost* Ghosts::find(std::uint32_t artifact) const { return const_cast<Ghosts*>(this)->find(artifact); }

void Ghosts::start(World& world, PhysicEngine& engine) {
  for (Ghost& g : ghosts_) {
    ArtifactData& data = world.artifact_data[g.artifact];
    const Artifact& a = *world.artifacts[g.artifact];
    g.body = data.body_begin;
    g.root_in_body = world.nodes[a.root().nodeIndex()].pose_in_body;
    engine.setKinematic(g.body);
    const auto e = g.stream.dueAt(0.0);
    g.lost = !e || e->lost;
    data.silent = g.lost;
    if (!g.lost) {
      engine.setState(g.body, bodyState(*e, g.root_in_body));
      g.tracked = true;
    }
  }
}

void Ghosts::adopt(PhysicEngine& engine) const {
  for (const Ghost& g : ghosts_) engine.setKinematic(g.body);
}

void Ghosts::beforePhysics(World& world, PhysicEngine& engine, double t_next, double dt) {
  for (Ghost& g : ghosts_) {
    const auto e = g.stream.dueAt(t_next);
    const BodyState& now = world.states[static_cast<std::size_t>(g.body)];
    if (!e || e->lost) {
      BodyState held;  // where it is, still
      held.pose = now.pose;
      engine.setState(g.body, held);
      continue;
    }
    const BodyState target = bodyState(*e, g.root_in_body);
    if (g.lost) {
      // found (again): put there, not swept across the world in one step
      engine.setState(g.body, target);
      continue;
    }
    // from where it is to where it will be, in this step: what the contacts see
    BodyState s;
    s.pose = now.pose;
    s.linear_velocity = (target.pose.position - now.pose.position) / dt;
    s.angular_velocity = rotationBetween(now.pose.orientation, target.pose.orientation) / dt;
    engine.setState(g.body, s);
  }
}

void Ghosts::afterPhysics(World& world, PhysicEngine& engine, double t_next, const Environment& env) {
  for (Ghost& g : ghosts_) {
    const auto e = g.stream.dueAt(t_next);
    const bool lost = !e || e->lost;
    if (lost != g.lost) setLost(g, lost, world, env, t_next);
    if (lost) continue;
    engine.setState(g.body, bodyState(*e, g.root_in_body));  // exactly the pose at t_next
    ages_.add(e->age);
  }
}

void Ghosts::setLost(Ghost& g, bool lost, World& world, const Environment& env, double t) {
  const std::string& name = world.artifacts[g.artifact]->name();
  if (lost) {
    const auto newest = g.stream.newest();
    env.log(LogLevel::Warning, "ghost '" + name + "' lost at t=" + seconds(t) + " s: no pose since t=" +
                                   seconds(newest.value_or(0)) + " s (timeout " + seconds(g.stream.settings().timeout) +
                                   " s); it holds where it was and its sensors are silent");
  } else if (g.tracked) {
    env.log(LogLevel::Info, "ghost '" + name + "' tracked again at t=" + seconds(t) + " s");
  }
  g.tracked = g.tracked || !lost;
  g.lost = lost;
  world.artifact_data[g.artifact].silent = lost;
}

void Ghosts::save(StateWriter& out) const {
  out.write(static_cast<std::uint64_t>(ghosts_.size()));
  for (const Ghost& g : ghosts_) {
    out.write(static_cast<std::uint8_t>(g.lost ? 1 : 0));
    g.stream.saveState(out);
  }
}

void Ghosts::load(StateReader& in, World& world) {
  const auto n = in.get<std::uint64_t>();
  if (n != ghosts_.size())
    throw StateError("saved state: " + std::to_string(n) + " ghosts, this world " + std::to_string(ghosts_.size()));
  // everything read before anything changes
  std::vector<PoseStream> streams;
  std::vector<bool> lost;
  for (const Ghost& g : ghosts_) {
    const auto flag = in.get<std::uint8_t>();
    if (flag > 1) throw StateError("saved state: a ghost's lost flag is neither 0 nor 1 (corrupted)");
    lost.push_back(flag == 1);
    streams.emplace_back(g.stream.settings());
    streams.back().loadState(in);
  }
  for (std::size_t i = 0; i < ghosts_.size(); ++i) {
    ghosts_[i].stream = std::move(streams[i]);
    ghosts_[i].lost = lost[i];
    world.artifact_data[ghosts_[i].artifact].silent = lost[i];
  }
}

}  // namespace ssx::detail

namespace ssx {

void Environment::setGhost(Artifact& artifact, const PoseStream::Settings& settings) {
  requireSetup("setGhost is allowed");
  detail::World& w = *world_;
  const std::size_t i = artifact.index();
  if (i >= w.artifacts.size() || w.artifacts[i].get() != &artifact)
    throw ConfigError({}, "setGhost: artifact '" + artifact.name() + "' belongs to another environment");
  auto refuse = [&](const std::string& why) { throw ConfigError({}, "artifact '" + artifact.name() + "' cannot be a ghost: " + why); };
  if (ghosts_->find(static_cast<std::uint32_t>(i)) != nullptr) refuse("it is one already");
  if (artifact.rootCount() != 1 || artifact.root().isStatic())
    refuse("a ghost is one dynamic physic tree (it has " + std::to_string(artifact.rootCount()) + " roots" +
           (artifact.rootCount() == 1 ? ", static" : "") + ")");
  if (artifact.driver() != nullptr)
    refuse("it has a driver ('" + artifact.driver()->className() +
           "'); a ghost moves by the poses it is given alone: leave the driver out");
  try {
    ghosts_->add(static_cast<std::uint32_t>(i), settings);
  } catch (const std::invalid_argument& e) {
    refuse(e.what());
  }
}

bool Environment::isGhost(const Artifact& artifact) const {
  return ghosts_->find(static_cast<std::uint32_t>(artifact.index())) != nullptr;
}

void Environment::setExternalPose(std::string_view name, const Pose& pose, double stamp) {
  requireOutsidePhases("setExternalPose");
  const Artifact* a = findArtifact(name);
  detail::Ghosts::Ghost* g = a == nullptr ? nullptr : ghosts_->find(static_cast<std::uint32_t>(a->index()));
  if (g == nullptr)
    throw Error("setExternalPose: '" + std::string(name) + "' is not a ghost" +
                (a == nullptr ? " (no artifact has that name)" : " (make it one with setGhost, or <ghost/> in the scene)"));
  g->stream.add(stamp, pose);
}

Environment::GhostStatus Environment::ghostStatus(const Artifact& artifact) const {
  const detail::Ghosts::Ghost* g = ghosts_->find(static_cast<std::uint32_t>(artifact.index()));
  if (g == nullptr) throw Error("ghostStatus: '" + artifact.name() + "' is not a ghost");
  GhostStatus s;
  s.samples = g->stream.size();
  const auto e = g->stream.dueAt(toSeconds(time()));
  s.lost = world_->started() ? g->lost : (!e || e->lost);
  s.age = e ? e->age : 0;
  return s;
}

AgeSummary Environment::ghostAges() const { return ghosts_->ages(); }

}  // namespace ssx
