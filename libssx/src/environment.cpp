#include "phase_guard.hpp"
#include "neighbor_index.hpp"
#include "render/scene_cameras.hpp"
#include "worker_pool.hpp"

#include <ssx/environment.hpp>
#include <ssx/plugin_abi.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <numbers>
#include <set>
#include <sstream>

namespace ssx {

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

bool finite(const BodyState& s) {
  return s.pose.position.allFinite() && s.pose.orientation.coeffs().allFinite() && s.linear_velocity.allFinite() &&
         s.angular_velocity.allFinite();
}

bool finite(const Wrench& w) { return w.force.allFinite() && w.torque.allFinite(); }

std::string describe(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& ex) {
    return ex.what();
  } catch (...) {
    return "unknown exception";
  }
}

void checkSettings(const EnvironmentSettings& s) {
  auto bad = [](const std::string& what) { throw ConfigError({}, what); };
  if (s.timestep <= 0) bad("timestep must be positive");
  if (s.threads < 0) bad("threads must be 0 (one per core), 1 (inline) or more");
  if (s.physics.substeps < 1) bad("physics substeps must be at least 1");
  if (s.physics.iterations < 1) bad("physics iterations must be at least 1");
  if (s.physics.max_contacts < 1) bad("physics max_contacts must be at least 1");
  if (!s.physics.gravity.allFinite()) bad("gravity must be finite");
  if (s.render.period_steps < 0) bad("render period must be 0 (never) or positive");
  if (!(s.render.rate_hz >= 0) || !std::isfinite(s.render.rate_hz)) bad("render rate_hz must be 0 or positive");
  if (s.render.width < 1 || s.render.height < 1 || s.render.width > kMaxImageSide || s.render.height > kMaxImageSide)
    bad("render width and height must be in 1.." + std::to_string(kMaxImageSide));
  for (const auto& c : s.render.cameras)
    if (!validFieldOfView(c.fov_deg)) bad("camera '" + c.name + "': fov_deg must be in (0, 180)");
}

}  // namespace

Environment::Environment(EnvironmentSettings settings)
    : settings_(std::move(settings)),
      loader_(std::make_unique<ClassLoader>()),
      cameras_(std::make_unique<detail::SceneCameras>()),
      neighbors_(std::make_unique<detail::NeighborIndex>()) {
  checkSettings(settings_);
  RenderSettings& r = settings_.render;
  if (r.rate_hz > 0)
    r.period_steps = std::max<std::int64_t>(1, std::llround(1.0 / (r.rate_hz * toSeconds(settings_.timestep))));
  // a camera with somewhere to put its frames and no rate given: 25 frames per simulated second
  if (r.period_steps == 0 && !r.cameras.empty())
    r.period_steps = std::max<std::int64_t>(1, std::llround(1.0 / (25.0 * toSeconds(settings_.timestep))));
}

Environment::~Environment() {
  try {
    stop();
  } catch (const std::exception& e) {
    log(LogLevel::Error, std::string("while stopping: ") + e.what());
  }
  // plugin instances go before the artifacts and extension slots that point at them
  loader_->destroyInstances();
}

void Environment::requireSetup(const char* what) const {
  if (state_ != State::Setup) throw Error(std::string(what) + " only before the environment starts");
}

Artifact& Environment::addArtifact(std::string name, const Pose& placement) {
  requireSetup("artifacts can be added");
  if (name.empty()) throw ConfigError({}, "an artifact needs a name");
  if (findArtifact(name) != nullptr) throw ConfigError({}, "duplicate artifact name '" + name + "'");
  artifacts_.push_back(std::unique_ptr<Artifact>(new Artifact(*this, std::move(name), artifacts_.size(), placement)));
  artifact_names_.emplace(artifacts_.back()->name(), artifacts_.back().get());
  return *artifacts_.back();
}

Artifact& Environment::addGround(double z) {
  Artifact& ground = addArtifact("ground", Pose{Vec3(0, 0, z), Quat::Identity()});
  PhysicNodeSpec plane;
  plane.name = "ground";
  plane.is_static = true;
  plane.shapes.push_back(Shape::plane());
  ground.addPhysicRoot(std::move(plane));
  RenderNodeSpec floor;
  floor.name = "ground";
  floor.primitive = RenderNodeSpec::Primitive::Plane;
  floor.size = Vec3(400, 400, 0);
  floor.color = {0.58f, 0.6f, 0.56f, 1.0f};
  floor.grid = true;
  ground.addRenderRoot(std::move(floor));
  return ground;
}

SimulationExtension& Environment::addExtension(std::string name, std::unique_ptr<SimulationExtension> extension,
                                               Descriptor params) {
  if (!extension) throw Error("addExtension given a null extension");
  SimulationExtension& e = addExtension(std::move(name), *extension, std::move(params));
  extensions_.back().owned = std::move(extension);
  return e;
}

SimulationExtension& Environment::addExtension(std::string name, SimulationExtension& extension, Descriptor params) {
  requireSetup("extensions can be added");
  if (name.empty()) throw ConfigError(params.where(), "an extension needs a name");
  if (this->extension(name) != nullptr) throw ConfigError(params.where(), "duplicate extension name '" + name + "'");
  extensions_.push_back({std::move(name), &extension, nullptr, std::move(params), false});
  return extension;
}

void Environment::subscribe(const Sensor& sensor, Artifact& subscriber,
                            std::function<void(const Measurement&)> callback) {
  requireOutsidePhases("subscribe");
  if (state_ != State::Setup && !configuring_)
    throw Error("subscriptions are made before the environment starts or from configure");
  if (&subscriber.environment() != this || sensor.artifact_ == nullptr || &sensor.artifact().environment() != this)
    throw Error("subscribe: sensor and subscriber must belong to this environment");
  const Artifact& source = sensor.artifact();
  subscriber.inbox_.push_back({&source, sensor.plugin_index_ - 1u, subscription_sequence_++, std::move(callback)});
}

void Environment::setLogSink(LogSink sink) { log_ = std::move(sink); }

void Environment::log(LogLevel level, std::string_view message) const {
  if (log_) {
    log_(level, message);
    return;
  }
  // diagnostics that already carry "file:line: warning:" are printed as they are
  if (message.find(": warning: ") != std::string_view::npos || message.find(": error: ") != std::string_view::npos) {
    std::cerr << message << '\n';
    return;
  }
  const char* tag = level == LogLevel::Error ? "error" : level == LogLevel::Warning ? "warning" : "info";
  std::cerr << "ssx: " << tag << ": " << message << '\n';
}

unsigned Environment::threadCount() const noexcept {
  if (pool_) return pool_->size();
  if (settings_.threads > 0) return static_cast<unsigned>(settings_.threads);
  return std::max(1u, std::thread::hardware_concurrency());
}

Artifact* Environment::findArtifact(std::string_view name) const {
  const auto it = artifact_names_.find(std::string(name));
  return it == artifact_names_.end() ? nullptr : it->second;
}

std::vector<Artifact*> Environment::selectArtifacts(std::string_view names) const {
  std::vector<Artifact*> out;
  if (names == "*") {
    for (const auto& a : artifacts_)
      if (a->rootCount() > 0 && !a->root().isStatic()) out.push_back(a.get());
    return out;
  }
  std::istringstream in{std::string(names)};
  std::string name;
  while (in >> name) {
    Artifact* a = findArtifact(name);
    if (a == nullptr) throw Error("no artifact named '" + name + "'");
    if (a->rootCount() == 0) throw Error("artifact '" + name + "' has no physic node");
    out.push_back(a);
  }
  return out;
}

SimulationExtension* Environment::extension(std::string_view name) const {
  for (const auto& e : extensions_)
    if (e.name == name) return e.extension;
  return nullptr;
}

const PhysicEngine& Environment::physics() const {
  if (!physics_) throw Error("the physics engine exists only while the environment runs");
  return *physics_;
}

RenderEngine& Environment::renderer() const {
  if (!renderer_) throw Error("the render engine exists only while the environment runs");
  return *renderer_;
}

// --- lifecycle ---------------------------------------------------------------------------------

void Environment::buildBodies() {
  // flatten each node tree into one rigid body whose frame is the tree's centre-of-mass frame
  for (auto& artifact : artifacts_) {
    artifact->body_begin_ = static_cast<int>(physics_->bodyCount());
    for (PhysicNode* root : artifact->roots_) {
      const PhysicNodeSpec& spec = root->spec();
      std::vector<Shape> shapes;
      std::vector<PhysicNode*> tree;  // the root and its descendants, in order
      for (auto& n : artifact->nodes_) {
        const PhysicNode* r = n.get();
        while (r->parent_ != nullptr) r = r->parent_;
        if (r == root) tree.push_back(n.get());
      }
      if (spec.is_static) {
        for (PhysicNode* n : tree) {
          n->pose_in_body_ = root->setup_pose_.inverse() * n->setup_pose_;
          for (Shape s : n->spec().shapes) {
            s.pose = n->pose_in_body_ * s.pose;
            shapes.push_back(s);
            static_shapes_.push_back({s, root->setup_pose_ * s.pose, artifact->index()});
          }
        }
        physics_->addStatic(shapes, root->setup_pose_);
        continue;
      }
      const MassProperties mass = combinedMass(spec);
      const Pose root_in_body{-mass.center_of_mass, Quat::Identity()};
      for (PhysicNode* n : tree) {
        n->pose_in_body_ = root_in_body * (root->setup_pose_.inverse() * n->setup_pose_);
        for (Shape s : n->spec().shapes) {
          s.pose = n->pose_in_body_ * s.pose;
          shapes.push_back(s);
        }
      }
      BodyState initial;
      initial.pose = root->setup_pose_ * root_in_body.inverse();
      initial.angular_velocity = root->initial_angular_;
      initial.linear_velocity =
          root->initial_linear_ + root->initial_angular_.cross(initial.pose.position - root->setup_pose_.position);
      const int body = physics_->addBody(mass, shapes, initial);
      for (PhysicNode* n : tree) n->body_ = body;
      body_owner_.push_back(artifact.get());
    }
    artifact->body_end_ = static_cast<int>(physics_->bodyCount());
  }
  states_.assign(physics_->bodyCount(), BodyState{});
  previous_linear_.assign(states_.size(), Vec3::Zero());
  previous_angular_.assign(states_.size(), Vec3::Zero());
  wrenches_.assign(states_.size(), Wrench{});
}

void Environment::checkDeclaredParameters() {
  // instances made by the class loader get their declared defaults and checks here too when a
  // program attached them itself (the scene loader has done it already: then nothing changes)
  std::string errors;
  auto check = [&](const void* instance, Descriptor& params, const Artifact* a, std::int64_t period,
                   const std::string& what) {
    const ssx_plugin_class* type = loader_->classOf(instance);
    if (type == nullptr) return;
    const PluginContext context{this, a, period, settings_.timestep, {}};
    for (const auto& d : checkParameters({type->params, type->param_count}, params, context, what))
      if (d.severity == Diagnostic::Severity::Error) errors += (errors.empty() ? "" : "\n") + d.str();
  };
  for (auto& e : extensions_) check(e.extension, e.params, nullptr, 1, "extension '" + e.name + "'");
  for (auto& a : artifacts_) {
    if (a->driver_ != nullptr)
      check(a->driver_, a->driver_params_, a.get(), a->driver_->periodSteps(), "driver '" + a->driver_->className() + "'");
    for (auto& s : a->sensors_)
      check(s.sensor, s.params, a.get(), s.sensor->periodSteps(), "sensor '" + s.sensor->className() + "'");
  }
  if (!errors.empty()) throw Error(errors + "\nnothing was run");
}

void Environment::start() {
  if (state_ == State::Running) return;
  requireSetup("start() is allowed");
  checkDeclaredParameters();
  try {
    // extensions first, in the order they were added
    for (auto& e : extensions_) {
      e.extension->init(*this, e.params);
      e.initialised = true;
    }
    physics_ = createPhysicEngine(settings_.physics);
    renderer_ = createRenderEngine(settings_.render);
    buildBodies();
    publishSnapshot(true);
    cameras_->start(settings_.render, settings_.timestep, *renderer_, artifacts_,
                    [this](std::string_view m) { log(LogLevel::Warning, m); });
    const unsigned threads = settings_.threads > 0 ? static_cast<unsigned>(settings_.threads)
                                                   : std::max(1u, std::thread::hardware_concurrency());
    pool_ = std::make_unique<detail::WorkerPool>(threads);
    errors_.assign(artifacts_.size(), PendingError{});
    state_ = State::Running;  // configure may subscribe and read the snapshot
    configuring_ = true;
    for (auto& a : artifacts_) {
      // sensors first: a driver may read their configuration (rates, resolutions)
      for (auto& s : a->sensors_) s.sensor->configure(s.params);
      if (a->driver_) a->driver_->configure(a->driver_params_);
    }
    configuring_ = false;
    warnUnusedParameters();
    // callbacks are delivered by source artifact, then sensor, then subscription order
    for (auto& a : artifacts_) {
      std::sort(a->inbox_.begin(), a->inbox_.end(), [](const auto& x, const auto& y) {
        if (x.source->index() != y.source->index()) return x.source->index() < y.source->index();
        if (x.sensor_index != y.sensor_index) return x.sensor_index < y.sensor_index;
        return x.sequence < y.sequence;
      });
    }
  } catch (...) {
    configuring_ = false;
    state_ = State::Failed;
    stop();
    throw;
  }
}

void Environment::stop() {
  if (state_ == State::Stopped) return;
  const bool started = state_ != State::Setup;
  state_ = State::Stopped;
  if (started) {
    // plugins first, then engines, then extensions in reverse order
    for (auto& a : artifacts_) {
      auto destroy = [&](Plugin& p, const std::string& what) {
        try {
          p.destroy();
        } catch (const std::exception& e) {
          log(LogLevel::Error, "artifact '" + a->name() + "', " + what + ": destroy threw: " + e.what());
        }
      };
      if (a->driver_) destroy(*a->driver_, "driver '" + a->driver_->className() + "'");
      for (auto& s : a->sensors_) destroy(*s.sensor, "sensor '" + s.sensor->className() + "'");
    }
    pool_.reset();
    cameras_->finish([this](std::string_view m) { log(LogLevel::Error, m); });
    renderer_.reset();
    physics_.reset();
  }
  for (auto it = extensions_.rbegin(); it != extensions_.rend(); ++it) {
    if (!it->initialised) continue;
    it->initialised = false;
    try {
      it->extension->shutdown(*this);
    } catch (const std::exception& e) {
      log(LogLevel::Error, "extension '" + it->name + "': shutdown threw: " + e.what());
    }
  }
}

void Environment::fail() { state_ = State::Failed; }

void Environment::warnUnusedParameters() const {
  // parameters no plugin read are typos or leftovers: say so once per place they were written
  std::set<std::string> seen;
  auto report = [&](const Descriptor& d) {
    for (auto& w : d.unusedAttributeWarnings())
      if (seen.insert(w).second) log(LogLevel::Warning, w);
  };
  for (const auto& e : extensions_) report(e.params);
  for (const auto& a : artifacts_) {
    if (a->driver_ != nullptr) report(a->driver_params_);
    for (const auto& s : a->sensors_) report(s.params);
  }
}

// --- one step ----------------------------------------------------------------------------------

void Environment::publishSnapshot(bool first) {
  if (!first) {
    for (std::size_t i = 0; i < states_.size(); ++i) {
      previous_linear_[i] = states_[i].linear_velocity;
      previous_angular_[i] = states_[i].angular_velocity;
    }
  }
  physics_->readStates(states_);
  const double inv_dt = 1.0 / toSeconds(settings_.timestep);
  const double max_v2 = settings_.physics.max_linear_speed * settings_.physics.max_linear_speed;
  const double max_w2 = settings_.physics.max_angular_speed * settings_.physics.max_angular_speed;
  for (std::size_t i = 0; i < states_.size(); ++i) {
    BodyState& s = states_[i];
    if (!finite(s) || s.linear_velocity.squaredNorm() > max_v2 || s.angular_velocity.squaredNorm() > max_w2) {
      fail();
      throw StepError(body_owner_[i]->name(), "physics", steps_ - 1,
                      "the simulation diverged: the state is NaN, infinite or faster than max_linear_speed / "
                      "max_angular_speed (an absurd force, or a timestep too large for the contacts)");
    }
    if (first) continue;
    s.linear_acceleration = (s.linear_velocity - previous_linear_[i]) * inv_dt;
    s.angular_acceleration = (s.angular_velocity - previous_angular_[i]) * inv_dt;
  }
}

void Environment::requireOutsidePhases(const char* what) const {
  // the parallel phases read what these calls change: a call from there would be a data race
  if (detail::PhaseGuard::in_phase)
    throw Error(std::string(what) + " is not allowed from a " + detail::PhaseGuard::role +
                " (the parallel phases): call it from configure, or between steps");
}

void Environment::enableNeighborQueries(double cell_size) {
  requireOutsidePhases("enableNeighborQueries");
  if (neighbors_->enable(cell_size) && state_ == State::Running) neighbors_->rebuild(artifacts_);
}

bool Environment::neighborQueriesEnabled() const noexcept { return neighbors_->enabled(); }

void Environment::neighbors(const Vec3& point, double radius, std::vector<std::size_t>& out) const {
  neighbors_->query(point, radius, out);
}

void Environment::neighbors(const Vec3& point, double radius, std::vector<SpatialIndex::Hit>& out) const {
  neighbors_->query(point, radius, out);
}

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
      if (!finite(wrenches_[static_cast<std::size_t>(b)])) {
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

std::vector<CameraSpec> Environment::cameras() const { return cameras_->specs(); }

const std::vector<RenderNode>& Environment::renderNodes() const noexcept { return cameras_->renderNodes(); }

std::int64_t Environment::frameCount() const noexcept { return cameras_->frameCount(); }

void Environment::addCameraRequest(std::string owner, std::function<bool(std::int64_t, CameraView&)> due,
                                   Image& target) {
  requireOutsidePhases("addCameraRequest");
  if (state_ != State::Running || !renderer_) throw Error("addCameraRequest: call it from a plugin's configure");
  if (!renderer_->drawsPixels())
    throw ConfigError({}, owner + " needs images, but render engine '" + renderer_->name() +
                              "' draws none: choose engine=\"osmesa\" in <render> or --render osmesa");
  cameras_->addRequest(std::move(owner), std::move(due), target);
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
        if (!finite(states_[i])) who = body_owner_[i]->name();
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

std::uint64_t Environment::stateHash() const {
  // FNV-1a over the raw bits of every pose and velocity, then the step count
  std::uint64_t h = 0xcbf29ce484222325ULL;
  auto mix = [&h](const double* p, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      std::uint64_t bits;
      std::memcpy(&bits, p + i, sizeof bits);
      for (int k = 0; k < 8; ++k) {
        h ^= (bits >> (8 * k)) & 0xffU;
        h *= 0x100000001b3ULL;
      }
    }
  };
  for (const auto& s : states_) {
    mix(s.pose.position.data(), 3);
    mix(s.pose.orientation.coeffs().data(), 4);
    mix(s.linear_velocity.data(), 3);
    mix(s.angular_velocity.data(), 3);
  }
  const double steps = static_cast<double>(steps_);
  mix(&steps, 1);
  return h;
}

}  // namespace ssx
