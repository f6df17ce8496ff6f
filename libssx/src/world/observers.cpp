// What is attached to a run and taken off again between steps without changing it: extensions
// added while running (observers: a viewer, a bridge) and renderers drawing the scene cameras'
// frames. Neither is part of a saved state nor of the scene's fingerprint, so a run gives the
// same bits whatever is attached and when.
#include "plugin/presets.hpp"
#include "render/scene_cameras.hpp"
#include "world/world.hpp"

#include <ssx/environment.hpp>
#include <ssx/error.hpp>

#include <algorithm>

namespace ssx {

namespace {

// render settings that draw no frame (the engine, size and looks kept)
void noFrames(RenderSettings& r) {
  r.cameras.clear();
  r.period_steps = 0;
  r.rate_hz = 0;
}

}  // namespace

void Environment::requireBetweenSteps(const char* what) const {
  requireOutsidePhases(what);
  const detail::World& w = *world_;
  if (w.stepping)
    throw Error(std::string(what) + " is not allowed from inside a step (an extension's hook or a step listener): "
                                    "call it between steps");
  if (w.configuring) throw Error(std::string(what) + " is not allowed from configure: call it between steps");
  if (w.state == State::Stopped || w.state == State::Failed)
    throw Error(std::string(what) + ": the environment " + (w.state == State::Failed ? "failed" : "was stopped"));
}

// an extension made by the class loader gets the checks of one added before start (presets,
// declared parameters, the class's validate), before its init
void Environment::checkObserver(const SimulationExtension& extension, Descriptor& params, const std::string& name) const {
  const ssx_plugin_class* type = loader_->classOf(&extension);
  if (type == nullptr || !params.declarations().empty()) return;  // not the loader's, or checked already
  const PluginContext context{this, nullptr, 1, settings_.timestep, {}};
  std::string errors;
  for (const auto& d : detail::Presets::installed().checkInstance(params, *type, context, "extension '" + name + "'"))
    if (d.severity == Diagnostic::Severity::Error) errors += (errors.empty() ? "" : "\n") + d.str();
  if (!errors.empty()) throw ConfigError({}, errors + "\nnothing was attached");
}

SimulationExtension& Environment::addExtension(std::string name, SimulationExtension& extension, Descriptor params) {
  if (world_->state == State::Running) return attachExtension(std::move(name), extension, std::move(params));
  requireSetup("extensions can be added");
  if (name.empty()) throw ConfigError(params.where(), "an extension needs a name");
  if (this->extension(name) != nullptr) throw ConfigError(params.where(), "duplicate extension name '" + name + "'");
  extensions_.push_back({std::move(name), &extension, nullptr, std::move(params), false, false});
  return extension;
}

SimulationExtension& Environment::attachExtension(std::string name, SimulationExtension& extension, Descriptor params) {
  requireBetweenSteps("attachExtension");
  if (name.empty()) throw ConfigError(params.where(), "an extension needs a name");
  if (this->extension(name) != nullptr) throw ConfigError(params.where(), "duplicate extension name '" + name + "'");
  const bool running = world_->state == State::Running;
  if (running) checkObserver(extension, params, name);  // (before start: start checks it with the others)
  extensions_.push_back({std::move(name), &extension, nullptr, std::move(params), false, true});
  if (!running) return extension;
  // it starts now, and observes (or steers) from the next step on
  try {
    extension.init(*this, extensions_.back().params);
  } catch (...) {
    extensions_.pop_back();
    throw;
  }
  extensions_.back().initialised = true;
  return extension;
}

bool Environment::removeExtension(std::string_view name) {
  requireBetweenSteps("removeExtension");
  const auto it = std::find_if(extensions_.begin(), extensions_.end(), [&](const ExtensionSlot& e) { return e.name == name; });
  if (it == extensions_.end()) return false;
  if (world_->state == State::Setup) {
    extensions_.erase(it);
    return true;
  }
  if (!it->observer)
    throw Error("removeExtension: extension '" + it->name + "' is part of the scene (added before start, its state in "
                "every saved state) and stays until stop(); observers (attachExtension) come off while running");
  ExtensionSlot slot = std::move(*it);
  extensions_.erase(it);
  // (the slot is kept until its shutdown returned: an extension the environment owns dies with it)
  try {
    slot.extension->shutdown(*this);
  } catch (const std::exception& e) {
    throw Error("extension '" + slot.name + "': shutdown: " + e.what());
  }
  return true;
}

void Environment::attachRenderer(RenderSettings render) {
  requireBetweenSteps("attachRenderer");
  detail::checkRenderSettings(render);
  detail::resolveRenderPeriod(render, settings_.timestep);
  detail::World& w = *world_;
  if (w.state == State::Setup) {
    settings_.render = std::move(render);  // what the run starts with
    return;
  }
  // camera sensors keep the engine they configured with (their images feed the simulation)
  std::unique_ptr<RenderEngine> engine;
  if (render.engine != renderer_->name()) {
    if (cameras_->hasRequests())
      throw ConfigError({}, "attachRenderer: camera sensors draw with render engine '" + renderer_->name() +
                                "': pictures while they run use it too (asked for '" + render.engine + "')");
    engine = createRenderEngine(render);
  }
  // what could refuse the settings is checked before the frames being drawn are finished
  cameras_->checkCameras(render, w.artifacts);
  std::string finished;
  try {
    cameras_->close();
  } catch (const std::exception& e) {
    finished = e.what();
  }
  if (engine) renderer_ = std::move(engine);
  settings_.render = std::move(render);
  try {
    cameras_->schedule(settings_.render, w.steps, *renderer_, w.artifacts);
  } catch (const std::exception& e) {
    noFrames(settings_.render);  // (the outputs could not be opened: nothing is scheduled)
    throw Error("attachRenderer: " + std::string(e.what()) +
                (finished.empty() ? "" : "; and the frames drawn before could not be finished: " + finished));
  }
  if (!finished.empty()) throw Error("attachRenderer: the frames drawn before could not be finished: " + finished);
}

void Environment::detachRenderer() {
  requireBetweenSteps("detachRenderer");
  noFrames(settings_.render);
  if (world_->state == State::Setup) return;
  try {
    cameras_->close();
  } catch (const std::exception& e) {
    throw Error(std::string("detachRenderer: ") + e.what());
  }
}

}  // namespace ssx
