#include "world/ghosts.hpp"
#include "world/neighbor_index.hpp"
#include "world/phase_guard.hpp"
#include "world/phases.hpp"
#include "render/scene_cameras.hpp"
#include "engines/state_checks.hpp"
#include "world/world.hpp"
#include "plugin/presets.hpp"
#include "base/worker_pool.hpp"

#include <ssx/environment.hpp>
#include <ssx/plugin_abi.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <iterator>
#include <numbers>
#include <set>
#include <sstream>

namespace ssx {

namespace {

void checkSettings(const EnvironmentSettings& s) {
  auto bad = [](const std::string& what) { throw ConfigError({}, what); };
  if (s.timestep <= 0) bad("timestep must be positive");
  if (s.timestep > toNanoseconds(kMaxTimestepSeconds)) bad("timestep must be at most 1 s");
  if (s.threads < 0) bad("threads must be 0 (one per core), 1 (inline) or more");
  const auto engines = physicEngineNames();
  if (std::find(engines.begin(), engines.end(), s.physics.engine) == engines.end())
    bad("unknown physics engine '" + s.physics.engine + "' (available: ode, bullet)");
  if (s.physics.substeps < 1) bad("physics substeps must be at least 1");
  if (s.physics.ode.iterations < 1 || s.physics.bullet.iterations < 1) bad("physics iterations must be at least 1");
  if (s.physics.ode.max_contacts < 1) bad("physics max_contacts must be at least 1");
  if (s.physics.ode.partitions < 1) bad("physics partitions must be at least 1");
  if (!s.physics.gravity.allFinite()) bad("gravity must be finite");
  detail::checkRenderSettings(s.render);
}

}  // namespace

Environment::Environment(EnvironmentSettings settings)
    : settings_(std::move(settings)),
      loader_(std::make_unique<ClassLoader>()),
      world_(std::make_unique<detail::World>(*this, settings_)),
      cameras_(std::make_unique<detail::SceneCameras>()),
      neighbors_(std::make_unique<detail::NeighborIndex>()),
      ghosts_(std::make_unique<detail::Ghosts>()) {
  checkSettings(settings_);
  detail::resolveRenderPeriod(settings_.render, settings_.timestep);
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

Environment::State Environment::state() const noexcept { return world_->state; }
std::int64_t Environment::stepCount() const noexcept { return world_->steps; }
std::size_t Environment::artifactCount() const noexcept { return world_->artifacts.size(); }
Artifact& Environment::artifact(std::size_t index) { return *world_->artifacts.at(index); }
const Artifact& Environment::artifact(std::size_t index) const { return *world_->artifacts.at(index); }
const BodyState& Environment::bodyState(int i) const { return world_->states.at(static_cast<std::size_t>(i)); }
std::size_t Environment::bodyCount() const noexcept { return world_->states.size(); }

const Artifact& Environment::bodyOwner(int i) const {
  return *world_->artifacts[world_->body_owner.at(static_cast<std::size_t>(i))];
}

const Artifact& Environment::contactOther(const EngineContact& contact) const {
  if (contact.body_b >= 0) return bodyOwner(contact.body_b);
  return *world_->artifacts[world_->static_group_owner.at(static_cast<std::size_t>(contact.static_group))];
}

void Environment::recordContacts(bool on) {
  requireOutsidePhases("recordContacts");
  world_->record_contacts = on;
  if (physics_) physics_->recordContacts(on);
}

const std::vector<EngineContact>& Environment::contacts() const {
  if (!world_->record_contacts || !physics_)
    throw Error("contacts: they are not recorded: call recordContacts(true) before the steps whose contacts you want");
  return physics_->contacts();
}

void Environment::setBodyState(int i, const BodyState& state) {
  requireOutsidePhases("setBodyState");
  if (world_->state != State::Running) throw Error("setBodyState: the environment is not running");
  if (i < 0 || static_cast<std::size_t>(i) >= world_->states.size())
    throw Error("setBodyState: no body " + std::to_string(i) + " (there are " + std::to_string(bodyCount()) + ")");
  const PhysicsSettings& ps = settings_.physics;
  if (!detail::finite(state) || state.linear_velocity.norm() > ps.max_linear_speed ||
      state.angular_velocity.norm() > ps.max_angular_speed)
    throw Error("setBodyState: body " + std::to_string(i) + " of artifact '" +
                world_->artifacts[world_->body_owner[static_cast<std::size_t>(i)]]->name() +
                "': the state must be finite and within max_linear_speed / max_angular_speed");
  rays_stale_ = true;
  BodyState& b = world_->states[static_cast<std::size_t>(i)];
  b.pose = state.pose;
  b.pose.orientation.normalize();
  b.linear_velocity = state.linear_velocity;
  b.angular_velocity = state.angular_velocity;
  physics_->setState(i, b);
}

void Environment::requireSetup(const char* what) const {
  if (world_->state != State::Setup) throw Error(std::string(what) + " only before the environment starts");
}

Artifact& Environment::addArtifact(std::string name, const Pose& placement) {
  requireSetup("artifacts can be added");
  if (name.empty()) throw ConfigError({}, "an artifact needs a name");
  if (findArtifact(name) != nullptr) throw ConfigError({}, "duplicate artifact name '" + name + "'");
  detail::World& w = *world_;
  w.artifacts.push_back(std::make_unique<Artifact>(w, std::move(name), w.artifacts.size(), placement));
  w.artifact_data.emplace_back();
  w.models.emplace_back();
  w.names.emplace(w.artifacts.back()->name(), w.artifacts.back().get());
  return *w.artifacts.back();
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

void Environment::subscribe(const Sensor& sensor, Artifact& subscriber,
                            std::function<void(const Measurement&)> callback) {
  requireOutsidePhases("subscribe");
  detail::World& w = *world_;
  if (w.state != State::Setup && !w.configuring)
    throw Error("subscriptions are made before the environment starts or from configure");
  if (&subscriber.environment() != this || !sensor.attached() || &sensor.artifact().environment() != this)
    throw Error("subscribe: sensor and subscriber must belong to this environment");
  const Artifact& source = sensor.artifact();
  const auto& sensors = w.data(source).sensors;
  std::uint32_t k = 0;
  while (sensors[k].sensor != &sensor) ++k;  // attached there: it is in the list
  w.data(subscriber).inbox.push_back({static_cast<std::uint32_t>(source.index()), k, w.subscription_sequence++,
                                      &sensor, sensors[k].plugin, std::move(callback)});
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

const Artifact* Environment::findArtifact(std::string_view name) const {
  return const_cast<Environment*>(this)->findArtifact(name);
}

Artifact* Environment::findArtifact(std::string_view name) {
  const auto it = world_->names.find(std::string(name));
  return it == world_->names.end() ? nullptr : it->second;
}

std::vector<const Artifact*> Environment::selectArtifacts(std::string_view names) const {
  const std::vector<Artifact*> chosen = const_cast<Environment*>(this)->selectArtifacts(names);
  return {chosen.begin(), chosen.end()};
}

std::vector<const Artifact*> Environment::selectArtifacts(const Descriptor& params, std::string_view key,
                                                          std::string_view purpose) const {
  const std::vector<Artifact*> chosen = const_cast<Environment*>(this)->selectArtifacts(params, key, purpose);
  return {chosen.begin(), chosen.end()};
}

std::vector<Artifact*> Environment::selectArtifacts(std::string_view names) {
  std::vector<Artifact*> out;
  if (names == "*") {
    for (const auto& a : world_->artifacts)
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

std::vector<Artifact*> Environment::selectArtifacts(const Descriptor& params, std::string_view key,
                                                    std::string_view purpose) {
  const std::string names = params.get<std::string>(key);
  try {
    return selectArtifacts(names);
  } catch (const Error& e) {
    throw params.errorAt(key, std::string(e.what()) + " to " + std::string(purpose));
  }
}

SimulationExtension* Environment::extension(std::string_view name) const {
  for (const auto& e : extensions_)
    if (e.name == name) return e.extension;
  return nullptr;
}

std::vector<std::string> Environment::extensionNames() const {
  std::vector<std::string> out;
  for (const auto& e : extensions_) out.push_back(e.name);
  return out;
}

const PhysicEngine& Environment::physics() const {
  if (!physics_) throw Error("the physics engine exists only while the environment runs");
  return *physics_;
}

const RenderEngine& Environment::renderer() const {
  if (!renderer_) throw Error("the render engine exists only while the environment runs");
  return *renderer_;
}

// --- lifecycle ---------------------------------------------------------------------------------

void Environment::checkDeclaredParameters() {
  // instances made by the class loader get their declared defaults and checks here too when a
  // program attached them itself (the scene loader has done it already: then nothing changes)
  std::string errors;
  // presets by name from the installed directory (the scene loader also searches its artifact path)
  std::optional<detail::Presets> presets;
  // `what` names the plugin, made only when its parameters are checked here
  auto check = [&](const void* instance, Descriptor& params, const Artifact* a, std::int64_t period, auto what) {
    if (!params.declarations().empty()) return;  // checked already (by the scene loader)
    const ssx_plugin_class* type = loader_->classOf(instance);
    if (type == nullptr) return;
    const PluginContext context{this, a, period, settings_.timestep, {}};
    if (!presets) presets.emplace(detail::Presets::installed());
    // and the class's own checks (what a scene's plugins get from the loader), before anything is
    // initialised: a plugin added by a program is refused with the environment still in setup
    const std::vector<Diagnostic> found = presets->checkInstance(params, *type, context, what());
    for (const auto& d : found)
      if (d.severity == Diagnostic::Severity::Error) errors += (errors.empty() ? "" : "\n") + d.str();
  };
  for (auto& e : extensions_)
    check(e.extension, e.params, nullptr, 1, [&] { return "extension '" + e.name + "'"; });
  for (auto& a : world_->artifacts) {
    detail::ArtifactData& data = world_->data(*a);
    detail::ArtifactModel& model = world_->model(*a);
    if (Driver* d = data.driver)
      check(d, model.driver_params, a.get(), d->periodSteps(), [&] { return "driver '" + d->className() + "'"; });
    for (std::size_t k = 0; k < data.sensors.size(); ++k) {
      Sensor* s = data.sensors[k].sensor;
      check(s, model.sensor_params[k], a.get(), s->periodSteps(), [&] { return "sensor '" + s->className() + "'"; });
    }
  }
  if (!errors.empty()) throw Error(errors + "\nnothing was run");
}

void Environment::start() {
  detail::World& w = *world_;
  if (w.state == State::Running) return;
  requireSetup("start() is allowed");
  checkDeclaredParameters();
  try {
    // extensions first, in the order they were added
    for (auto& e : extensions_) {
      e.extension->init(*this, e.params);
      e.initialised = true;
    }
    physics_ = createPhysicEngine(settings_.physics);
    physics_->recordContacts(w.record_contacts);  // (asked for before start)
    w.engine = physics_.get();
    renderer_ = createRenderEngine(settings_.render);
    detail::buildBodies(w, *physics_, &static_shapes_);
    ghosts_->start(w, *physics_);
    detail::applyPresence(w, *physics_, {});
    detail::publishSnapshot(w, *physics_, true);
    // (queries enabled before start, by an extension's init, see the first snapshot too)
    if (neighbors_->enabled()) neighbors_->markStale(w);
    cameras_->bind(w.artifacts, settings_.timestep, settings_.render.background,
                   [this](std::string_view m) { log(LogLevel::Warning, m); });
    cameras_->schedule(settings_.render, 0, *renderer_, w.artifacts);
    const unsigned threads = settings_.threads > 0 ? static_cast<unsigned>(settings_.threads)
                                                   : std::max(1u, std::thread::hardware_concurrency());
    pool_ = std::make_unique<detail::WorkerPool>(threads);
    physics_->setTaskRunner(pool_.get());
    w.errors.assign(w.artifacts.size(), detail::PendingError{});
    w.state = State::Running;  // configure may subscribe and read the snapshot
    w.configuring = true;
    PluginSetup::SharedValues shared;  // what the instances of a class compute alike, while they configure
    for (std::size_t i = 0; i < w.artifacts.size(); ++i) {
      const detail::ArtifactData& data = w.artifact_data[i];
      const detail::ArtifactModel& model = w.models[i];
      // sensors first: a driver may read their configuration (rates, resolutions)
      for (std::size_t k = 0; k < data.sensors.size(); ++k) {
        PluginSetup setup(*this, *data.sensors[k].sensor, &shared);
        data.sensors[k].sensor->configure(model.sensor_params[k], setup);
      }
      if (data.driver) {
        PluginSetup setup(*this, *data.driver, &shared);
        data.driver->configure(model.driver_params, setup);
      }
    }
    w.configuring = false;
    warnUnusedParameters();
    // callbacks are delivered by source artifact, then sensor, then subscription order
    for (auto& data : w.artifact_data) {
      std::sort(data.inbox.begin(), data.inbox.end(), [](const auto& x, const auto& y) {
        if (x.source != y.source) return x.source < y.source;
        if (x.sensor_index != y.sensor_index) return x.sensor_index < y.sensor_index;
        return x.sequence < y.sequence;
      });
    }
    // the phases' tables: every artifact's sensor slots and subscriptions in one array each, in
    // artifact order (a step walks them front to back; separate blocks would be a cache miss per
    // artifact with thousands of them)
    w.sensor_slots.clear();
    w.subscriptions.clear();
    for (auto& data : w.artifact_data) {
      data.sensor_begin = static_cast<std::uint32_t>(w.sensor_slots.size());
      w.sensor_slots.insert(w.sensor_slots.end(), data.sensors.begin(), data.sensors.end());
      data.sensor_end = static_cast<std::uint32_t>(w.sensor_slots.size());
      data.inbox_begin = static_cast<std::uint32_t>(w.subscriptions.size());
      std::move(data.inbox.begin(), data.inbox.end(), std::back_inserter(w.subscriptions));
      data.inbox_end = static_cast<std::uint32_t>(w.subscriptions.size());
      data.inbox.clear();
      data.inbox.shrink_to_fit();
    }
  } catch (...) {
    w.configuring = false;
    w.state = State::Failed;
    stop();
    throw;
  }
}

void Environment::stop() {
  detail::World& w = *world_;
  if (w.state == State::Stopped) return;
  const bool started = w.state != State::Setup;
  w.state = State::Stopped;
  // everything is stopped whatever fails; what failed is reported together at the end
  std::vector<std::string> failures;
  auto failed = [&](std::string what) { failures.push_back(std::move(what)); };
  if (started) {
    // plugins first, then engines, then extensions in reverse order
    for (auto& a : w.artifacts) {
      detail::ArtifactData& data = w.data(*a);
      auto destroy = [&](Plugin& p, const std::string& what) {
        try {
          p.destroy();
        } catch (const std::exception& e) {
          failed("artifact '" + a->name() + "', " + what + ": destroy threw: " + e.what());
        }
      };
      if (data.driver) destroy(*data.driver, "driver '" + data.driver->className() + "'");
      for (auto& s : data.sensors) destroy(*s.sensor, "sensor '" + s.sensor->className() + "'");
    }
    if (physics_) physics_->setTaskRunner(nullptr);
    pool_.reset();
    try {
      cameras_->close();
    } catch (const std::exception& e) {
      failed(e.what());
    }
    renderer_.reset();
    physics_.reset();
  }
  for (auto it = extensions_.rbegin(); it != extensions_.rend(); ++it) {
    if (!it->initialised) continue;
    it->initialised = false;
    try {
      it->extension->shutdown(*this);
    } catch (const std::exception& e) {
      failed("extension '" + it->name + "': shutdown: " + e.what());
    }
  }
  if (failures.empty()) return;
  std::string message = failures.front();
  for (std::size_t i = 1; i < failures.size(); ++i) message += "; " + failures[i];
  throw Error(message);
}

void Environment::fail() { world_->state = State::Failed; }

void Environment::warnUnusedParameters() const {
  // parameters no plugin read are typos or leftovers: say so once per place they were written
  std::set<std::string> seen;
  auto report = [&](const Descriptor& d) {
    for (auto& w : d.unusedAttributeWarnings())
      if (seen.insert(w).second) log(LogLevel::Warning, w);
  };
  for (const auto& e : extensions_) report(e.params);
  for (const auto& model : world_->models) {
    report(model.driver_params);  // empty when there is no driver
    for (const auto& params : model.sensor_params) report(params);
  }
}

void Environment::requireOutsidePhases(const char* what) const {
  // the parallel phases read what these calls change: a call from there would be a data race
  if (detail::PhaseGuard::now.in_phase)
    throw Error(std::string(what) + " is not allowed from a " + detail::PhaseGuard::now.role +
                " (the parallel phases): call it from configure, or between steps");
}

void Environment::enableNeighborQueries(double cell_size) {
  requireOutsidePhases("enableNeighborQueries");
  if (neighbors_->enable(cell_size) && world_->state == State::Running) neighbors_->markStale(*world_);
}

bool Environment::neighborQueriesEnabled() const noexcept { return neighbors_->enabled(); }

void Environment::neighbors(const Vec3& point, double radius, std::vector<std::size_t>& out) const {
  neighbors_->query(point, radius, out);
}

void Environment::neighbors(const Vec3& point, double radius, std::vector<SpatialIndex::Hit>& out) const {
  neighbors_->query(point, radius, out);
}

void Environment::forEachNeighbor(const Vec3& point, double radius, SpatialIndex::Visitor visit, void* context) const {
  neighbors_->forEach(point, radius, visit, context);
}

std::vector<CameraSpec> Environment::cameras() const { return cameras_->specs(); }

const std::vector<RenderNode>& Environment::renderNodes() const noexcept { return cameras_->renderNodes(); }

std::int64_t Environment::frameCount() const noexcept { return cameras_->frameCount(); }

void Environment::drawFrame(Nanoseconds time, std::span<const RenderNode> overlay) {
  requireOutsidePhases("drawFrame");
  if (world_->state != State::Running) throw Error("drawFrame: the environment is not running");
  cameras_->invalidate();  // the bodies may have moved without a step: pose the items again
  cameras_->drawFrame(world_->steps, world_->artifacts, time, overlay);
}

void Environment::addCameraRequest(std::string owner, std::function<bool(std::int64_t, CameraView&)> due,
                                   Image& target) {
  requireOutsidePhases("addCameraRequest");
  if (world_->state != State::Running || !renderer_) throw Error("addCameraRequest: call it from a plugin's configure");
  if (!renderer_->drawsPixels())
    throw ConfigError({}, owner + " needs images, but render engine '" + renderer_->name() +
                              "' draws none: choose engine=\"osmesa\" in <render> or --render osmesa");
  cameras_->addRequest(std::move(owner), std::move(due), target);
}

}  // namespace ssx
