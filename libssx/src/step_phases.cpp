// One step: physics, snapshot, the sensors and drivers phases on the worker pool, render, and the
// extensions' hooks around them (the order is documented in environment.hpp).
#include "neighbor_index.hpp"
#include "phase_guard.hpp"
#include "render/scene_cameras.hpp"
#include "state_checks.hpp"
#include "worker_pool.hpp"

#include <ssx/environment.hpp>

#include <algorithm>
#include <chrono>

namespace ssx {

// defined here, where the phases set them around every plugin call: in the same translation
// unit the accesses need no call into the dynamic linker's TLS lookup
namespace detail {
thread_local bool PhaseGuard::in_phase = false;
thread_local const Artifact* PhaseGuard::writer = nullptr;
thread_local const char* PhaseGuard::role = "";
}  // namespace detail

namespace {

using Clock = std::chrono::steady_clock;

Nanoseconds since(Clock::time_point t0) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count();
}

std::string describe(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& ex) {
    return ex.what();
  } catch (...) {
    return "unknown exception";
  }
}

}  // namespace

namespace {
// With thousands of robots a phase is bound by memory latency: every robot's objects live in
// their own heap blocks. Loading the next robots' objects while this one runs hides part of it.
void prefetch(const void* p, std::size_t bytes = 64) {
  for (std::size_t offset = 0; offset < bytes; offset += 64) __builtin_prefetch(static_cast<const char*>(p) + offset);
}
}  // namespace

void Environment::prefetchArtifact(std::size_t i, std::size_t end, bool sensors) const {
  if (i + 2 < end) prefetch(artifacts_[i + 2].get(), sizeof(Artifact));
  if (i + 1 >= end) return;
  const Artifact& next = *artifacts_[i + 1];
  if (sensors) {
    for (const auto& slot : next.sensors_) prefetch(slot.sensor, 256);
  } else {
    if (next.driver_ != nullptr) prefetch(next.driver_, 512);
    if (!next.inbox_.empty()) prefetch(next.inbox_.data(), next.inbox_.size() * sizeof(next.inbox_[0]));
  }
}

void Environment::runSensors(std::size_t begin, std::size_t end) {
  const StepInfo base{current_step_, time(), 0};
  for (std::size_t i = begin; i < end; ++i) {
    prefetchArtifact(i, end, true);
    Artifact& a = *artifacts_[i];
    for (std::size_t k = 0; k < a.sensors_.size(); ++k) {
      auto& slot = a.sensors_[k];
      slot.fresh = false;
      Sensor& sensor = *slot.sensor;
      if (current_step_ % sensor.period_steps_ != 0) continue;
      StepInfo info = base;
      info.period = sensor.period_steps_ * settings_.timestep;
      try {
        detail::PhaseGuard guard(nullptr, "sensor");
        sensor.sense(info);
        slot.fresh = true;
      } catch (...) {
        errors_[i] = {"sensor " + std::to_string(k) + " '" + sensor.className() + "'",
                      describe(std::current_exception())};
        break;
      }
    }
  }
}

void Environment::runDrivers(std::size_t begin, std::size_t end) {
  const StepInfo base{current_step_, time(), 0};
  for (std::size_t i = begin; i < end; ++i) {
    prefetchArtifact(i, end, false);
    Artifact& a = *artifacts_[i];
    if (!errors_[i].plugin.empty()) continue;
    // deliver fresh measurements, in the order fixed at start
    const Artifact::Subscription* current = nullptr;
    try {
      detail::PhaseGuard guard(nullptr, "callback");
      for (const auto& sub : a.inbox_) {
        const auto& slot = sub.source->sensors_[sub.sensor_index];
        if (!slot.fresh) continue;
        current = &sub;
        sub.callback(slot.sensor->latest());
      }
    } catch (...) {
      errors_[i] = {"callback subscribed to sensor '" +
                        current->source->sensors_[current->sensor_index].sensor->className() + "' of artifact '" +
                        current->source->name() + "'",
                    describe(std::current_exception())};
      continue;
    }
    Driver* driver = a.driver_;
    if (driver == nullptr || current_step_ % driver->period_steps_ != 0) continue;
    StepInfo info = base;
    info.period = driver->period_steps_ * settings_.timestep;
    for (int b = a.body_begin_; b < a.body_end_; ++b) wrenches_[static_cast<std::size_t>(b)] = Wrench{};
    try {
      detail::PhaseGuard guard(&a, "driver");
      driver->step(info);
    } catch (...) {
      errors_[i] = {"driver '" + driver->className() + "'", describe(std::current_exception())};
      continue;
    }
    for (int b = a.body_begin_; b < a.body_end_; ++b) {
      if (!detail::finite(wrenches_[static_cast<std::size_t>(b)])) {
        errors_[i] = {"driver '" + driver->className() + "'", "applied a NaN or infinite force or torque"};
        break;
      }
    }
  }
}

void Environment::raiseFirstError(const char* phase) {
  // the lowest artifact index wins, so the report does not depend on the thread count
  for (std::size_t i = 0; i < errors_.size(); ++i) {
    if (errors_[i].plugin.empty()) continue;
    fail();
    throw StepError(artifacts_[i]->name(), errors_[i].plugin, current_step_,
                    std::string(errors_[i].message) + " (in the " + phase + " phase)");
  }
}

void Environment::step() {
  if (state_ == State::Setup) start();
  if (state_ != State::Running)
    throw Error(state_ == State::Failed ? "the environment failed in an earlier step; it cannot step again"
                                        : "the environment is stopped");
  const auto t_step = Clock::now();
  StepTiming timing;
  current_step_ = steps_;
  timing.step = current_step_;

  runExtensionHook(&SimulationExtension::beforeStep, "beforeStep");

  // physics, with the actuation written before
  auto t = Clock::now();
  try {
    physics_->step(settings_.timestep, wrenches_);
  } catch (const std::exception& e) {
    // the engine gave up (ODE reports a NaN it met as an internal error): name the first
    // artifact whose state is no longer finite, if the engine can still tell
    fail();
    std::string who;
    try {
      physics_->readStates(states_);
      for (std::size_t i = 0; i < states_.size() && who.empty(); ++i)
        if (!detail::finite(states_[i])) who = body_owner_[i]->name();
    } catch (...) {
    }
    throw StepError(who, "physics", current_step_, e.what());
  }
  timing.physics = since(t);
  t = Clock::now();
  for (const auto& a : artifacts_)
    if (!a->driver_)
      for (int b = a->body_begin_; b < a->body_end_; ++b) wrenches_[static_cast<std::size_t>(b)] = Wrench{};
  ++steps_;
  publishSnapshot(false);
  if (neighbors_->enabled()) neighbors_->rebuild(artifacts_);
  timing.snapshot = since(t);
  if (cameras_->hasRequests()) {
    t = Clock::now();
    try {
      cameras_->renderRequests(current_step_, *renderer_, settings_.render.background, artifacts_);
    } catch (...) {
      fail();
      throw;
    }
    timing.render += since(t);
  }

  const std::size_t n = artifacts_.size();
  const std::size_t chunk = std::max<std::size_t>(1, n / (pool_->size() * 8));
  // sensors, in parallel
  t = Clock::now();
  auto sensors = [this](std::size_t b, std::size_t e) { runSensors(b, e); };
  pool_->parallelFor(n, chunk, sensors);
  timing.sensors = since(t);
  raiseFirstError("sensors");

  // callbacks and drivers, in parallel
  t = Clock::now();
  auto drivers = [this](std::size_t b, std::size_t e) { runDrivers(b, e); };
  pool_->parallelFor(n, chunk, drivers);
  timing.drivers = since(t);
  raiseFirstError("drivers");

  // render, when due
  if (settings_.render.period_steps > 0 && current_step_ % settings_.render.period_steps == 0) {
    t = Clock::now();
    try {
      cameras_->drawFrame(current_step_, settings_.render, artifacts_);
    } catch (...) {
      fail();
      throw;
    }
    timing.render += since(t);
  }

  runExtensionHook(&SimulationExtension::afterStep, "afterStep");
  timing.total = since(t_step);
  timing_.add(timing);
}

void Environment::runExtensionHook(void (SimulationExtension::*hook)(Environment&), const char* what) {
  for (auto& e : extensions_) {
    try {
      (e.extension->*hook)(*this);
    } catch (const std::exception& ex) {
      fail();
      throw StepError("", "extension '" + e.name + "'", current_step_, std::string(what) + ": " + ex.what());
    }
  }
}

void Environment::step(std::int64_t n) {
  for (std::int64_t i = 0; i < n; ++i) step();
}

}  // namespace ssx
