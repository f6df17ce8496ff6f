// Exchanging the physics engine while a run goes on: the same bodies, static shapes and joints
// made again in the other engine, as at start, then every body put where the snapshot has it.
// What the engine-independent world holds (the snapshot, the commands held, the joints' motor
// commands, the plugins' state, the random streams) stays as it is.
#include "base/worker_pool.hpp"
#include "world/ghosts.hpp"
#include "world/phase_guard.hpp"
#include "world/phases.hpp"
#include "world/world.hpp"

#include <ssx/environment.hpp>
#include <ssx/error.hpp>

#include <algorithm>

namespace ssx {

namespace {

void requireKnown(const std::string& engine, const char* what) {
  const auto names = physicEngineNames();
  if (std::find(names.begin(), names.end(), engine) != names.end()) return;
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  throw ConfigError({}, std::string(what) + ": unknown physics engine '" + engine + "' (available: " + list + ")");
}

}  // namespace

void Environment::switchPhysics(const std::string& engine) {
  requireKnown(engine, "switchPhysics");
  requireOutsidePhases("switchPhysics");
  detail::World& w = *world_;
  if (w.configuring) throw Error("switchPhysics is not allowed from configure: call it between steps");
  if (w.state == State::Setup) {
    settings_.physics.engine = engine;  // the engine the run starts with
    return;
  }
  if (w.state != State::Running) throw Error("switchPhysics: the environment failed or was stopped");
  if (engine == physics_->name()) return;
  const std::string from = physics_->name();
  exchangePhysics(engine);
  switches_.push_back({time(), from, engine});
}

void Environment::switchPhysicsAt(Nanoseconds at, const std::string& engine) {
  requireKnown(engine, "switchPhysicsAt");
  if (at < 0) throw ConfigError({}, "switchPhysicsAt: a negative time (" + std::to_string(at) + " ns)");
  // after those at the same time or earlier: carried out in the order given
  const auto where = std::upper_bound(scheduled_.begin(), scheduled_.end(), at,
                                      [](Nanoseconds t, const PhysicsSwitch& s) { return t < s.time; });
  scheduled_.insert(where, PhysicsSwitch{at, {}, engine});
}

void Environment::runScheduledSwitches() {
  while (!scheduled_.empty() && scheduled_.front().time <= time()) {
    const std::string engine = scheduled_.front().to;
    scheduled_.erase(scheduled_.begin());
    switchPhysics(engine);
  }
}

void Environment::exchangePhysics(const std::string& engine) {
  detail::World& w = *world_;
  PhysicsSettings settings = settings_.physics;
  settings.engine = engine;
  std::unique_ptr<PhysicEngine> next = createPhysicEngine(settings);
  // the rebuild rewrites the node and joint tables with the values they have (the engines number
  // bodies, static groups and joints in the order made); the run-time joints it makes again are
  // put back if the new engine refuses anything, so that the old one goes on as it was
  const std::vector<detail::Attachment> attachments = w.attachments;
  const std::vector<std::uint16_t> attached = w.attached;
  try {
    detail::buildBodies(w, *next, nullptr);
    ghosts_->adopt(*next);
    detail::applyPresence(w, *next, {});
    for (std::size_t i = 0; i < w.states.size(); ++i) next->setState(static_cast<int>(i), w.states[i]);
    detail::reattach(w, *next);
    detail::applyMassScales(w, *next);
  } catch (...) {
    w.attachments = attachments;
    w.attached = attached;
    throw;
  }
  next->setTaskRunner(pool_.get());
  next->recordContacts(w.record_contacts);
  physics_->setTaskRunner(nullptr);
  physics_ = std::move(next);
  w.engine = physics_.get();
  settings_.physics.engine = engine;
  rays_stale_ = true;
}

}  // namespace ssx
