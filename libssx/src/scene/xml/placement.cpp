// Placements: read from the scene into the model (<artifact>, <swarm> with its layout, <ground>,
// <obstacle>), then built: artifacts placed one by one, with their plugins created and every
// parameter checked against its class's declarations.
#include "scene/xml/layouts.hpp"
#include "scene/xml/scene_loader.hpp"

#include <ssx/plugin_abi.hpp>

#include "plugin/parameter_checks.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ssx::detail {

template <class T, class Create>
T* SceneLoader::createPlugin(const PluginDecl& decl, Create create) {
  // a plugin that failed once is reported once, not for every artifact of a swarm
  const std::string key = decl.plugin + "/" + decl.class_name;
  if (failed_plugins_.contains(key)) return nullptr;
  try {
    return &create(decl.plugin, decl.class_name);
  } catch (const PluginError& e) {
    error(decl.params.where(), "<" + decl.params.name() + ">: " + std::string(e.what()));
    failed_plugins_[key] = e.what();
    return nullptr;
  }
}

void SceneLoader::checkPlugin(Environment& env, const void* instance, Descriptor& params, const Artifact* artifact,
                              std::int64_t period_steps, const std::string& what, const SourceLocation& period_from,
                              const PluginDecl* decl, const Descriptor* overrides) {
  const ssx_plugin_class* type = env.classLoader().classOf(instance);
  if (type == nullptr) return;
  const std::span<const ssx_plugin_param> declarations{type->params, type->param_count};
  // a preset's values first: then they are checked as the element's own (the preset file is an input)
  if (!presets_) {
    std::vector<fs::path> dirs;
    for (const fs::path& d : options_.artifact_path) dirs.push_back(d / "presets");
    if (options_.search_installed_artifacts)
      if (fs::path installed = Presets::installedDirectory(); !installed.empty()) dirs.push_back(installed);
    presets_.emplace(std::move(dirs), options_.max_input_bytes);
  }
  fs::path preset_file;
  if (auto problems = presets_->apply(params, type->name, declarations, what, &preset_file); !problems.empty()) {
    // (once: a swarm's members share the preset, and its problem)
    for (auto& d : problems)
      if (reported_presets_.insert(d.str()).second) add(std::move(d));
    for (const auto& a : params.attributes()) a.used = true;
    params.setDeclarations(declarations);
    return;
  }
  if (!preset_file.empty()) files_.addInput(preset_file);
  // the declared checks read only the values, the period and the time step: once the parameters
  // of a declaration and a placing element passed, the next member of that swarm differs only in
  // the values where its index was put ({i}), and only those need checking
  const auto key = std::make_tuple(static_cast<const void*>(type), decl, overrides, period_steps);
  const auto clean = decl != nullptr ? clean_checks_.find(key) : clean_checks_.end();
  const PluginContext context{&env, artifact, period_steps, env.timestep(), period_from};
  std::vector<Diagnostic> found = detail::checkParametersNamed(
      declarations, params, context, what, clean != clean_checks_.end() ? &clean->second : nullptr);
  if (decl != nullptr && clean == clean_checks_.end() && found.empty()) {
    std::vector<std::string> per_member;
    if (overrides != nullptr)
      for (const auto& a : overrides->attributes())
        if (a.value.find("{i}") != std::string::npos) per_member.push_back(a.key);
    // (a preset that differs between members brings values that differ: each member checked whole)
    if (std::find(per_member.begin(), per_member.end(), "preset") == per_member.end())
      clean_checks_.emplace(key, std::move(per_member));
  }
  // the files it writes, with the run's others (only when its values are of the declared types)
  if (found.empty())
    for (const ssx_plugin_param& p : declarations) {
      if ((p.flags & SSX_PARAM_OUTPUT) == 0) continue;
      const auto* a = params.find(p.name);
      if (a == nullptr || a->value.empty()) continue;
      const SourceLocation where = a->where;
      std::string file = a->value;
      const bool moved = !options_.output_directory.empty() && fs::path(file).is_relative();
      // (the program makes the output directory after loading; deeper directories must exist)
      const bool in_made_directory = moved && fs::path(file).parent_path().empty();
      if (moved) {
        // into the run's output directory: the plugin opens it there
        file = (options_.output_directory / file).string();
        params.set(p.name, file, where);
      }
      if (auto problem = files_.claimOutput(file, "parameter '" + std::string(p.name) + "'", false, in_made_directory); !problem.empty())
        found.push_back({Diagnostic::Severity::Error, where, "<" + params.name() + ">: " + what + ": " + problem});
    }
  for (auto& d : found) add(std::move(d));
  // unknown parameters were reported just now: not again when the environment starts
  for (const auto& a : params.attributes()) a.used = true;
}

void SceneLoader::validatePlugin(Environment& env, const void* instance, const Descriptor& params,
                                 const Artifact* artifact, std::int64_t period_steps, const std::string& what) {
  const ssx_plugin_class* type = env.classLoader().classOf(instance);
  if (type == nullptr || type->validate == nullptr) return;
  const PluginContext context{&env, artifact, period_steps, env.timestep(), {}, &validate_shared_[type]};
  std::vector<Diagnostic> found;
  type->validate(&params, &context, &found);
  for (auto& d : found) {
    // named as the declared checks name it: "<driver>: driver 'quadrotor': ..."
    const std::string element = "<" + params.name() + ">: ";
    if (d.message.rfind(element, 0) == 0) d.message.erase(0, element.size());
    d.message = element + what + ": " + d.message;
    add(std::move(d));
  }
}

// the type's plugin parameters, with those given on the scene's <artifact> or <swarm> on top
Descriptor SceneLoader::withOverrides(const PluginDecl& decl, const Descriptor* overrides, const std::string& index) {
  if (overrides == nullptr) return decl.params;
  Descriptor params = decl.params;
  for (const auto& a : overrides->attributes()) {
    if (a.key == "index" || a.key == "period") continue;  // read by the loader, not plugin parameters
    // in a swarm, {i} in a value is the member's index
    std::string value = a.value;
    if (!index.empty())
      for (auto at = value.find("{i}"); at != std::string::npos; at = value.find("{i}", at + index.size()))
        value.replace(at, 3, index);
    params.set(a.key, value, a.where);
  }
  return params;
}

// the period in steps: the placing element's override, else the type's
std::int64_t SceneLoader::periodOf(const PluginDecl& decl, const Descriptor* overrides) {
  return overrides == nullptr ? decl.period : readCount(*overrides, "period", decl.period, 1);
}

// where the period in steps was set: the placing element's override, else the type's, if anywhere
SourceLocation SceneLoader::periodFrom(const PluginDecl& decl, const Descriptor* overrides) {
  if (overrides != nullptr)
    if (const auto* a = overrides->find("period")) return a->where;
  return decl.period_from;
}

// --- reading ---------------------------------------------------------------------------------

void SceneLoader::readPlacements() {
  std::size_t swarm_index = 0;
  for (std::size_t k = 0; k < entities_.size(); ++k) {
    stage_ = stage(2, 2 * static_cast<std::int64_t>(k));
    const Descriptor& d = *entities_[k].element;
    PlacementModel p;
    p.where = d.where();
    bool ok = true;
    // a name given empty would make an artifact nobody can name: an error, not a silent drop
    for (const char* key : {"name", "type"})
      if (const auto* a = d.find(key); a != nullptr && a->value.empty())
        error(a->where, "<" + d.name() + ">: attribute '" + key + "' is empty; give it a value");
    if (d.name() == "artifact") {
      p.kind = PlacementModel::Kind::Artifact;
      p.name = require(d, "name");
      p.type = require(d, "type");
      p.xyz = read<Vec3>(d, "xyz", Vec3::Zero());
      p.rpy = read<Vec3>(d, "rpy", Vec3::Zero());
      p.allow_overlap = read<bool>(d, "allow_overlap", false);
      checkUnknown(d, {"driver", "sensor", "ghost"});
      ok = !p.name.empty() && !p.type.empty() && readOverrides(d, p);
    } else if (d.name() == "swarm") {
      p.kind = PlacementModel::Kind::Swarm;
      ok = readSwarm(d, p, swarm_index++);
    } else if (d.name() == "ground") {
      p.kind = PlacementModel::Kind::Ground;
      p.name = "ground";
      p.xyz.z() = read<double>(d, "z", 0.0);
      checkUnknown(d);
    } else {
      p.kind = PlacementModel::Kind::Obstacle;
      ok = readObstacle(d, p);
    }
    if (!ok) continue;
    model_.placements.push_back(std::move(p));
    placement_stage_.push_back(stage_);
  }
}

// the type (read now, if it was not yet) and the parameters the placing element sets on its plugins
bool SceneLoader::readOverrides(const Descriptor& d, PlacementModel& p) {
  const ArtifactType* type = artifactType(p.type, d.where());
  if (const Descriptor* o = d.child("driver")) p.driver = std::make_shared<const Descriptor>(*o);
  if (type == nullptr) return true;  // reported; built as far as it goes (its name is still taken)
  p.sensors.assign(type->sensors.size(), nullptr);
  for (const Descriptor* o : d.childrenNamed("sensor")) {
    const std::int64_t i = read<std::int64_t>(*o, "index", 0);
    if (i < 0 || i >= static_cast<std::int64_t>(type->sensors.size())) {
      error(o->where(), "<sensor>: index " + std::to_string(i) + " does not name a sensor of type '" + p.type +
                            "' (it has " + std::to_string(type->sensors.size()) + ")");
      continue;
    }
    p.sensors[static_cast<std::size_t>(i)] = std::make_shared<const Descriptor>(*o);
  }
  if (p.driver != nullptr && !type->driver)
    error(p.driver->where(), "<driver>: artifact type '" + p.type + "' has no driver to set parameters of");
  if (const Descriptor* g = d.child("ghost")) {
    // a real robot: its poses from outside, interpolated to simulated time (PoseStream)
    PoseStream::Settings s;
    for (auto [key, value] : {std::pair{"timeout", &s.timeout}, std::pair{"horizon", &s.horizon}}) {
      const double v = read<double>(*g, key, *value);
      if (v >= 0 && v <= kMaxDurationSeconds)
        *value = v;
      else
        record(g->errorAt(key, std::string("attribute '") + key + "' must be 0 s or more, got '" + g->find(key)->value + "'"));
    }
    s.capacity = static_cast<std::size_t>(readCount(*g, "capacity", static_cast<std::int64_t>(s.capacity), 2, 1'000'000));
    checkUnknown(*g);
    if (p.driver != nullptr)
      error(p.driver->where(), "<driver>: '" + p.name + "' is a ghost (moved by the poses it is given): it runs no driver");
    p.ghost = s;
    p.ghost_where = g->where();
  }
  return true;
}

void SceneLoader::checkMemory(const Descriptor& d, const PlacementModel& p) {
  // what an artifact costs while it runs, measured (ssx run, 100,000 members, largest resident
  // size): a box 3.5 KiB, an mk_quad (one body, a driver, two sensors) 9 KiB. Estimated on the low
  // side (3 KiB a body, 1.5 KiB a plugin), so that only what cannot fit is refused.
  constexpr double kBytesPerBody = 3 << 10, kBytesPerPlugin = 1536;
  if (p.type.empty()) return;
  const ArtifactType* type = artifactType(p.type, d.where());
  if (type == nullptr) return;
  const double plugins = static_cast<double>(type->sensors.size()) + (type->driver ? 1 : 0);
  const double each = kBytesPerBody * static_cast<double>(std::max<std::size_t>(type->physic.size(), 1)) +
                      kBytesPerPlugin * plugins;
  placed_bytes_ += each * static_cast<double>(p.count);
  const double memory =
      options_.max_memory_bytes > 0
          ? static_cast<double>(options_.max_memory_bytes)
          : static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
  if (memory <= 0 || placed_bytes_ <= memory) return;
  constexpr double kGiB = 1 << 30;
  const double swarm = each * static_cast<double>(p.count);
  char text[240];
  std::snprintf(text, sizeof text, "<swarm>: %lld members of '%s' need about %.3g GiB (%.3g KiB each, estimated",
                static_cast<long long>(p.count), p.type.c_str(), swarm / kGiB, each / 1024);
  std::string message = text;
  if (placed_bytes_ > swarm) {
    std::snprintf(text, sizeof text, "; %.3g GiB with the artifacts before them", placed_bytes_ / kGiB);
    message += text;
  }
  std::snprintf(text, sizeof text, "), more than %s (%.3g GiB): make 'count' smaller",
                options_.max_memory_bytes > 0 ? "the memory allowed" : "this machine's memory", memory / kGiB);
  error(d.where(), message + text);
}

bool SceneLoader::readSwarm(const Descriptor& d, PlacementModel& p, std::size_t swarm_index) {
  const std::size_t errors_before = errorCount();
  p.type = require(d, "type");
  p.count = readCount(d, "count", 1, 1);
  p.name = read<std::string>(d, "name", p.type + "{i}");
  p.first_index = readCount(d, "first_index", 0, 0);
  p.layout = readChoice(d, "layout", "grid", {"grid", "random", "sphere"});
  p.xyz = read<Vec3>(d, "xyz", Vec3::Zero());
  p.rpy = read<Vec3>(d, "rpy", Vec3::Zero());
  const std::int64_t count = p.count;
  checkMemory(d, p);
  if (errorCount() != errors_before) return false;  // (its layout is not worked out)
  if (p.layout == "grid") {
    p.spacing = readPositive(d, "spacing", 1.0);
    p.columns = readCount(d, "columns", static_cast<std::int64_t>(std::ceil(std::sqrt(static_cast<double>(count)))), 1);
    p.rows = readCount(d, "rows", (count + p.columns - 1) / p.columns, 1);
    p.positions = detail::gridLayout(count, p.spacing, p.columns, p.rows);
  } else if (p.layout == "random") {
    p.min = read<Vec3>(d, "min", p.min);
    p.max = read<Vec3>(d, "max", p.max);
    if (!(p.min.array() <= p.max.array()).all()) error(d.where(), "<swarm>: every component of 'min' must be <= 'max'");
    p.min_distance = read<double>(d, "min_distance", 0.0);
    // a stream of its own, from the scene seed and the swarm's position among the swarms
    Random rng(deriveSeed(settings_.seed, 0xa11ce5ULL, swarm_index));
    p.positions = detail::randomLayout(count, p.min, p.max, p.min_distance, rng);
    if (static_cast<std::int64_t>(p.positions.size()) < count) {
      error(d.where(), "<swarm>: could not place " + std::to_string(count) + " members " +
                           std::to_string(p.min_distance) + " m apart in the box: enlarge it or lower min_distance");
      p.positions.resize(static_cast<std::size_t>(count), Vec3::Zero());
    }
  } else {
    p.radius = readPositive(d, "radius", 1.0);
    p.positions = detail::sphereLayout(count, p.radius);
  }
  p.allow_overlap = read<bool>(d, "allow_overlap", false);
  p.random_yaw = read<bool>(d, "random_yaw", false);
  if (p.random_yaw) {
    // a stream of its own, apart from the random layout's
    Random rng(deriveSeed(settings_.seed, 0x7a3ULL, swarm_index));
    p.yaws.resize(static_cast<std::size_t>(count));
    for (double& yaw : p.yaws) yaw = rng.uniform(-M_PI, M_PI);
  }
  checkUnknown(d, {"driver", "sensor", "ghost"});
  if (count > 1 && p.name.find("{i}") == std::string::npos)
    error(d.where(), "<swarm>: the name pattern '" + p.name + "' needs {i} to give " + std::to_string(count) +
                         " artifacts different names");
  if (p.type.empty() || errorCount() != errors_before) return false;
  readOverrides(d, p);
  return errorCount() == errors_before && types_.at(p.type).ok;
}

bool SceneLoader::readObstacle(const Descriptor& d, PlacementModel& p) {
  const std::size_t errors_before = errorCount();
  p.name = require(d, "name");
  p.xyz = read<Vec3>(d, "xyz", Vec3::Zero());
  p.rpy = read<Vec3>(d, "rpy", Vec3::Zero());
  p.allow_overlap = read<bool>(d, "allow_overlap", false);
  (void)readColor(d, {0.55f, 0.55f, 0.6f, 1.0f});
  bool shapes = false;
  for (const Descriptor& c : d.children()) {
    if (!kShapeElements.contains(c.name())) continue;
    (void)readShape(c);
    shapes = true;
  }
  checkUnknown(d, kShapeElements);
  if (!shapes) error(d.where(), "<obstacle>: needs at least one shape (box, sphere, cylinder, capsule)");
  if (p.name.empty() || errorCount() != errors_before) return false;
  p.obstacle = std::make_shared<const Descriptor>(d);
  return true;
}

// --- building ------------------------------------------------------------------------------------

bool SceneLoader::place(Environment& env, const std::string& name, const PlacementModel& p,
                        const ArtifactTypeModel& type, const Pose& pose, const std::string& index) {
  const SourceLocation& where = p.where;
  if (env.findArtifact(name) != nullptr) {
    error(where, "duplicate artifact name '" + name + "'");
    return false;
  }
  const Descriptor* driver_override = p.driver.get();
  const auto sensor_override = [&](std::size_t i) { return i < p.sensors.size() ? p.sensors[i].get() : nullptr; };
  Artifact& a = env.addArtifact(name, pose);
  const std::size_t errors_before = errorCount();
  for (const auto& r : type.physic) a.addPhysicRoot(r);
  for (const auto& r : type.render) a.addRenderRoot(r);
  ClassLoader& loader = env.classLoader();
  // each plugin's parameters are checked against its declarations as it is attached, then each
  // class's own checks run on the whole artifact (a driver may need a sensor of some kind)
  if (type.driver && !p.ghost) {
    const PluginDecl& decl = *type.driver;
    auto create = [&](std::string_view pl, std::string_view c) -> Driver& { return loader.createDriver(pl, c); };
    if (Driver* d = createPlugin<Driver>(decl, create)) {
      Descriptor params = withOverrides(decl, driver_override, index);
      const std::int64_t period = periodOf(decl, driver_override);
      checkPlugin(env, d, params, &a, period, "driver '" + decl.class_name + "'", periodFrom(decl, driver_override),
                  &decl, driver_override);
      a.setDriver(*d, std::move(params), period, decl.class_name);
    }
  }
  for (std::size_t i = 0; i < type.sensors.size(); ++i) {
    const PluginDecl& decl = type.sensors[i];
    auto create = [&](std::string_view pl, std::string_view c) -> Sensor& { return loader.createSensor(pl, c); };
    if (Sensor* s = createPlugin<Sensor>(decl, create)) {
      Descriptor params = withOverrides(decl, sensor_override(i), index);
      const std::int64_t period = periodOf(decl, sensor_override(i));
      checkPlugin(env, s, params, &a, period, "sensor " + std::to_string(i) + " '" + decl.class_name + "'",
                  periodFrom(decl, sensor_override(i)), &decl, sensor_override(i));
      a.addSensor(*s, std::move(params), period, decl.class_name);
    }
  }
  if (p.ghost) {
    try {
      env.setGhost(a, *p.ghost);
    } catch (const ConfigError& e) {
      error(p.ghost_where, std::string("<ghost>: ") + e.what());
    }
  }
  if (errorCount() != errors_before) return false;  // the class checks assume values of the declared types
  for (std::size_t i = 0; i < a.sensorCount(); ++i)
    validatePlugin(env, &a.sensor(i), a.sensorParameters(i), &a, a.sensor(i).periodSteps(),
                   "sensor " + std::to_string(i) + " '" + a.sensor(i).className() + "'");
  if (a.driver() != nullptr)
    validatePlugin(env, a.driver(), a.driverParameters(), &a, a.driver()->periodSteps(),
                   "driver '" + a.driver()->className() + "'");
  return errorCount() == errors_before;
}

void SceneLoader::buildObstacle(Environment& env, const PlacementModel& p) {
  const Descriptor& d = *p.obstacle;
  // (read and checked when parsed: what reading it again says was said then)
  const std::size_t said = diagnostics_.size();
  const auto color = readColor(d, {0.55f, 0.55f, 0.6f, 1.0f});
  PhysicNodeSpec spec;
  spec.name = p.name;
  spec.where = d.where();
  spec.is_static = true;
  RenderNodeSpec render;
  render.name = p.name;
  for (const Descriptor& c : d.children()) {
    if (!kShapeElements.contains(c.name())) continue;
    spec.shapes.push_back(readShape(c));
    RenderNodeSpec r = readRenderNode(c, false);
    r.color = color;
    render.children.push_back(std::move(r));
  }
  if (parsed_) {
    diagnostics_.resize(said);
    stamps_.resize(said);
  }
  if (env.findArtifact(p.name) != nullptr) {
    error(d.where(), "duplicate artifact name '" + p.name + "'");
    return;
  }
  Artifact& a = env.addArtifact(p.name, p.pose());
  a.addPhysicRoot(std::move(spec));
  a.addRenderRoot(std::move(render));
}

void SceneLoader::buildSwarm(Environment& env, const PlacementModel& p, const ArtifactTypeModel& type) {
  const Pose origin = p.pose();
  for (std::int64_t i = 0; i < p.count && static_cast<std::size_t>(i) < p.positions.size(); ++i) {
    Pose pose = origin;
    pose.position = origin.transformPoint(p.positions[static_cast<std::size_t>(i)]);
    if (static_cast<std::size_t>(i) < p.yaws.size())
      pose.orientation = (origin.orientation * Quat(Eigen::AngleAxisd(p.yaws[static_cast<std::size_t>(i)], Vec3::UnitZ()))).normalized();
    if (!place(env, p.memberName(i), p, type, pose, std::to_string(p.first_index + i)))
      return;  // one report per swarm, not one per robot
  }
}

}  // namespace ssx::detail
