// One step: physics, snapshot, the sensors and drivers phases on the worker pool, render, and the
// extensions' hooks around them (the order is documented in environment.hpp).
#include "world/ghosts.hpp"
#include "world/neighbor_index.hpp"
#include "world/phase_guard.hpp"
#include "world/phases.hpp"
#include "render/scene_cameras.hpp"
#include "engines/state_checks.hpp"
#include "base/exceptions.hpp"
#include "base/worker_pool.hpp"

#include <ssx/environment.hpp>

#include <algorithm>
#include <chrono>

namespace ssx {

// defined here, where the phases set them around every plugin call: in the same translation
// unit the accesses need no call into the dynamic linker's TLS lookup
namespace detail {
thread_local PhaseGuard::State PhaseGuard::now;
}  // namespace detail

namespace {

using Clock = std::chrono::steady_clock;

Nanoseconds since(Clock::time_point t0) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count();
}

// the time since `t`, and `t` moved to now
Nanoseconds lapTimer(Clock::time_point& t) {
  const auto now = Clock::now();
  const Nanoseconds elapsed = std::chrono::duration_cast<std::chrono::nanoseconds>(now - t).count();
  t = now;
  return elapsed;
}

}  // namespace

namespace {
// With thousands of robots a phase is bound by memory latency: every robot's objects live in
// their own heap blocks. Loading the next robots' objects while this one runs hides part of it.
void prefetch(const void* p, std::size_t bytes = 64) {
  for (std::size_t offset = 0; offset < bytes; offset += 64) __builtin_prefetch(static_cast<const char*>(p) + offset);
}
}  // namespace

namespace detail {

namespace {
void prefetchArtifact(const World& world, std::size_t i, std::size_t end, bool sensors) {
  // (the world's node, random-stream, artifact, sensor-slot and subscription tables are walked
  // in order: the hardware prefetcher follows them; what is scattered over the heap is what is
  // fetched here)
  if (i + 1 >= end) return;
  const ArtifactData& next = world.artifact_data[i + 1];
  // (the artifact, which sensors and drivers reach their nodes through)
  if (i + 2 < end) prefetch(world.artifacts[i + 2].get(), sizeof(Artifact));
  // its first node's handle and table row and its first body's snapshot, which every sensor and
  // driver reading its node's state reaches (in order in their tables, but among a dozen streams
  // the hardware's prefetcher does not follow them all: 8-12 % of a step at 100,000 robots)
  if (next.first_node < next.node_end) {
    prefetch(&world.node_handles[next.first_node]);
    prefetch(&world.nodes[next.first_node]);
  }
  if (next.body_begin < next.body_end)
    prefetch(&world.states[static_cast<std::size_t>(next.body_begin)], sizeof(BodyState));
  if (sensors) {
    for (std::uint32_t k = next.sensor_begin; k < next.sensor_end; ++k) prefetch(world.sensor_slots[k].sensor, 256);
    return;
  }
  // a driver's handles and state (the first 16 cache lines: a driver that keeps what every step
  // reads first, as the quadrotor's does, has it there) and the sensors its callbacks get
  if (next.driver != nullptr) prefetch(next.driver, 1024);
  for (std::uint32_t k = next.inbox_begin; k < next.inbox_end; ++k) prefetch(world.subscriptions[k].sensor);
}
}  // namespace

void runSensors(World& world, std::size_t begin, std::size_t end) {
  const std::int64_t step = world.current_step;
  const StepInfo base{step, world.steps * world.settings.timestep, 0};
  for (std::size_t i = begin; i < end; ++i) {
    prefetchArtifact(world, i, end, true);
    ArtifactData& a = world.artifact_data[i];
    for (std::uint32_t at = a.sensor_begin; at < a.sensor_end; ++at) {
      const std::size_t k = at - a.sensor_begin;
      const SensorSlot& slot = world.sensor_slots[at];
      std::uint8_t& fresh = world.fresh[slot.plugin];
      fresh = 0;
      if (a.silent || a.absent) continue;
      Sensor& sensor = *slot.sensor;
      const std::int64_t period = slot.period_steps;
      if (step % period != 0) continue;
      StepInfo info = base;
      info.period = period * world.settings.timestep;
      try {
        PhaseGuard guard(nullptr, "sensor");
        sensor.sense(info);
        if (!sensor.latest().finite()) {
          world.errors[i] = {"sensor " + std::to_string(k) + " '" + sensor.className() + "'",
                             "wrote a NaN or infinite value into its measurement"};
          break;
        }
        fresh = 1;
      } catch (...) {
        world.errors[i] = {"sensor " + std::to_string(k) + " '" + sensor.className() + "'",
                           describe(std::current_exception())};
        break;
      }
    }
  }
}

void runDrivers(World& world, std::size_t begin, std::size_t end) {
  const std::int64_t step = world.current_step;
  const StepInfo base{step, world.steps * world.settings.timestep, 0};
  for (std::size_t i = begin; i < end; ++i) {
    prefetchArtifact(world, i, end, false);
    ArtifactData& a = world.artifact_data[i];
    if (!world.errors[i].plugin.empty() || a.absent) continue;
    // deliver fresh measurements, in the order fixed at start
    const Subscription* current = nullptr;
    try {
      PhaseGuard guard(nullptr, "callback");
      for (std::uint32_t at = a.inbox_begin; at < a.inbox_end; ++at) {
        const Subscription& sub = world.subscriptions[at];
        if (world.fresh[sub.plugin] == 0) continue;
        current = &sub;
        sub.callback(sub.sensor->latest());
      }
    } catch (...) {
      world.errors[i] = {"callback subscribed to sensor '" + current->sensor->className() + "' of artifact '" +
                             world.artifacts[current->source]->name() + "'",
                         describe(std::current_exception())};
      continue;
    }
    Driver* driver = a.driver;
    if (driver == nullptr) continue;
    const std::int64_t period = a.driver_period;
    if (step % period != 0) continue;
    StepInfo info = base;
    info.period = period * world.settings.timestep;
    for (int b = a.body_begin; b < a.body_end; ++b) world.wrenches[static_cast<std::size_t>(b)] = Wrench{};
    try {
      PhaseGuard guard(world.artifacts[i].get(), "driver");
      driver->step(info);
    } catch (...) {
      world.errors[i] = {"driver '" + driver->className() + "'", describe(std::current_exception())};
      continue;
    }
    for (int b = a.body_begin; b < a.body_end; ++b) {
      const Wrench& w = world.wrenches[static_cast<std::size_t>(b)];
      if (!finite(w)) {
        world.errors[i] = {"driver '" + driver->className() + "'", "applied a NaN or infinite force or torque"};
        break;
      }
      if (!withinLimit(w, world.wrench_limits[static_cast<std::size_t>(b)])) {
        world.errors[i] = {"driver '" + driver->className() + "'",
                           "applied a force or torque that would change a body's speed by more than "
                           "max_linear_speed or max_angular_speed in one step"};
        break;
      }
    }
  }
}

void clearUndrivenCommands(World& world) {
  for (const ArtifactData& a : world.artifact_data)
    if (a.driver == nullptr)
      for (int b = a.body_begin; b < a.body_end; ++b) world.wrenches[static_cast<std::size_t>(b)] = Wrench{};
}

}  // namespace detail

void Environment::hotMemory(std::vector<MemoryRange>& out) const {
  const detail::World& w = *world_;
  if (w.artifacts.size() > 16) return;
  auto block = [&out](const void* p, std::size_t bytes) {
    if (p != nullptr && bytes > 0) out.push_back({p, bytes});
  };
  auto all = [&block](const auto& v) { block(v.data(), v.size() * sizeof(v[0])); };
  block(this, sizeof *this);
  block(&w, sizeof w);
  all(w.artifact_data);
  all(w.sensor_slots);
  all(w.subscriptions);
  all(w.fresh);
  all(w.errors);
  all(w.nodes);
  all(w.randoms);
  all(w.states);
  all(w.previous_linear);
  all(w.previous_angular);
  all(w.wrenches);
  all(w.wrench_limits);
  for (const auto& artifact : w.artifacts) block(artifact.get(), sizeof(Artifact));
  // a plugin's first 16 cache lines (a driver that keeps what every step reads first, as the
  // quadrotor's does, has it there), a sensor's first 8
  for (const detail::ArtifactData& a : w.artifact_data) block(a.driver, 1024);
  for (const detail::SensorSlot& slot : w.sensor_slots) block(slot.sensor, 512);
  physics_->hotMemory(out);
}

void Environment::raiseFirstError(const char* phase) {
  // the lowest artifact index wins, so the report does not depend on the thread count
  const detail::World& w = *world_;
  for (std::size_t i = 0; i < w.errors.size(); ++i) {
    if (w.errors[i].plugin.empty()) continue;
    fail();
    throw StepError(w.artifacts[i]->name(), w.errors[i].plugin, w.current_step,
                    std::string(w.errors[i].message) + " (in the " + phase + " phase)");
  }
}

void Environment::step() {
  detail::World& w = *world_;
  if (w.state == State::Setup) start();
  if (w.state != State::Running)
    throw Error(w.state == State::Failed ? "the environment failed in an earlier step; it cannot step again"
                                        : "the environment is stopped");
  if (!scheduled_.empty() && scheduled_.front().time <= time()) runScheduledSwitches();
  // (extensions, renderers and engines are exchanged between steps, not from the step's own hooks)
  struct Stepping {
    bool& flag;
    explicit Stepping(bool& f) : flag(f) { flag = true; }
    ~Stepping() { flag = false; }
  } stepping(w.stepping);
  // one clock reading ends a phase and starts the next (a lap timer): half the readings of a
  // start and an end per phase, which cost a twentieth of a small world's step; none at all
  // when no timing is kept
  const bool timed = settings_.timing_samples > 0;
  const auto t_step = timed ? Clock::now() : Clock::time_point{};
  auto t = t_step;
  auto lap = [timed](Clock::time_point& at) { return timed ? lapTimer(at) : Nanoseconds{0}; };
  StepTiming timing;
  w.current_step = w.steps;
  timing.step = w.current_step;

  runExtensionHook(&SimulationExtension::beforeStep, "beforeStep");

  // physics, with the actuation written before (and the ghosts moving to their next poses)
  lap(t);  // (the extensions' beforeStep counts in the total only)
  const double t_next = toSeconds((w.steps + 1) * settings_.timestep);
  try {
    if (!ghosts_->empty()) ghosts_->beforePhysics(w, *physics_, t_next, toSeconds(settings_.timestep));
    const Wrench* applied = w.joints.empty() ? w.wrenches.data() : detail::applyJoints(w, *physics_);
    physics_->step(settings_.timestep, {applied, w.wrenches.size()});
    if (!ghosts_->empty()) ghosts_->afterPhysics(w, *physics_, t_next, *this);
  } catch (const std::exception& e) {
    // the engine gave up (ODE reports a NaN it met as an internal error): name the first
    // artifact whose state is no longer finite, if the engine can still tell
    fail();
    std::string who;
    try {
      physics_->readStates(w.states);
      for (std::size_t i = 0; i < w.states.size() && who.empty(); ++i)
        if (!detail::finite(w.states[i])) who = w.artifacts[w.body_owner[i]]->name();
    } catch (...) {
    }
    throw StepError(who, "physics", w.current_step, e.what());
  }
  timing.physics = lap(t);
  detail::clearUndrivenCommands(w);
  ++w.steps;
  detail::publishSnapshot(w, *physics_, false);
  if (neighbors_->enabled()) neighbors_->markStale(w);
  if (rays_enabled_) {
    physics_->prepareRayQueries();
    rays_stale_ = false;
  }
  timing.snapshot = lap(t);
  if (cameras_->hasRequests()) {
    try {
      cameras_->renderRequests(w.current_step, *renderer_, w.artifacts);
    } catch (...) {
      fail();
      throw;
    }
    timing.render += lap(t);
  }

  const std::size_t n = w.artifacts.size();
  const std::size_t chunk = std::max<std::size_t>(1, n / (pool_->size() * 8));
  // sensors, in parallel
  auto sensors = [&w](std::size_t b, std::size_t e) { detail::runSensors(w, b, e); };
  pool_->parallelFor(n, chunk, sensors);
  timing.sensors = lap(t);
  raiseFirstError("sensors");

  // callbacks and drivers, in parallel
  auto drivers = [&w](std::size_t b, std::size_t e) { detail::runDrivers(w, b, e); };
  pool_->parallelFor(n, chunk, drivers);
  timing.drivers = lap(t);
  raiseFirstError("drivers");
  // the joints the drivers asked for, at the poses they saw (before anything else moves a body)
  if (w.attach_pending.load(std::memory_order_relaxed)) detail::applyAttachRequests(w, *physics_);

  // render, when due (the outputs opened at the first frame, finished after the last)
  if (cameras_->due(w.current_step)) {
    lap(t);  // (the attach requests before it count in the total only)
    try {
      cameras_->drawFrame(w.current_step, w.artifacts, -1, {}, true);
    } catch (...) {
      fail();
      throw;
    }
    timing.render += lap(t);
  }

  runExtensionHook(&SimulationExtension::afterStep, "afterStep");
  if (timed) {
    timing.total = since(t_step);
    timing_.add(timing);
  }
  for (std::size_t i = 0; i < listeners_.size(); ++i) {
    try {
      listeners_[i].second(*this);
    } catch (const std::exception& e) {
      fail();
      throw StepError("", "step listener", world_->current_step, e.what());
    }
  }
}

std::size_t Environment::addStepListener(std::function<void(const Environment&)> listener) {
  listeners_.emplace_back(next_listener_, std::move(listener));
  return next_listener_++;
}

void Environment::removeStepListener(std::size_t id) noexcept {
  std::erase_if(listeners_, [id](const auto& l) { return l.first == id; });
}

void Environment::runExtensionHook(void (SimulationExtension::*hook)(Environment&), const char* what) {
  for (auto& e : extensions_) {
    try {
      (e.extension->*hook)(*this);
    } catch (const std::exception& ex) {
      fail();
      throw StepError("", "extension '" + e.name + "'", world_->current_step, std::string(what) + ": " + ex.what());
    }
  }
}

void Environment::step(std::int64_t n) {
  for (std::int64_t i = 0; i < n; ++i) step();
}

}  // namespace ssx
