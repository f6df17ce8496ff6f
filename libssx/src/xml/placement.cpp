// Pass 2: artifacts placed one by one, as obstacles or as swarms, with their plugins created and
// every parameter checked against its class's declarations.
#include "xml/layouts.hpp"
#include "xml/scene_loader.hpp"

#include <ssx/plugin_abi.hpp>

#include "parameter_checks.hpp"

#include <cmath>

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
    clean_checks_.emplace(key, std::move(per_member));
  }
  for (auto& d : found) diagnostics_.push_back(std::move(d));
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
    diagnostics_.push_back(std::move(d));
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

void SceneLoader::place(Environment& env, const std::string& name, const std::string& type_name, const Pose& pose,
                        const Descriptor& element, const std::string& index) {
  const SourceLocation& where = element.where();
  const ArtifactType* type = artifactType(type_name, where);
  if (env.findArtifact(name) != nullptr) {
    error(where, "duplicate artifact name '" + name + "'");
    return;
  }
  if (type == nullptr) return;
  // parameter overrides: <driver .../> and <sensor index="i" .../> inside the placing element
  const Descriptor* driver_override = element.child("driver");
  std::vector<const Descriptor*> sensor_overrides(type->sensors.size(), nullptr);
  for (const Descriptor* o : element.childrenNamed("sensor")) {
    const std::int64_t i = read<std::int64_t>(*o, "index", 0);
    if (i < 0 || i >= static_cast<std::int64_t>(type->sensors.size())) {
      error(o->where(), "<sensor>: index " + std::to_string(i) + " does not name a sensor of type '" + type_name +
                            "' (it has " + std::to_string(type->sensors.size()) + ")");
      continue;
    }
    sensor_overrides[static_cast<std::size_t>(i)] = o;
  }
  if (driver_override != nullptr && !type->driver)
    error(driver_override->where(), "<driver>: artifact type '" + type_name + "' has no driver to set parameters of");

  Artifact& a = env.addArtifact(name, pose);
  const std::size_t errors_before = errorCount();
  for (const auto& p : type->physic) a.addPhysicRoot(p);
  for (const auto& r : type->render) a.addRenderRoot(r);
  ClassLoader& loader = env.classLoader();
  // each plugin's parameters are checked against its declarations as it is attached, then each
  // class's own checks run on the whole artifact (a driver may need a sensor of some kind)
  if (type->driver) {
    const PluginDecl& decl = *type->driver;
    auto create = [&](std::string_view p, std::string_view c) -> Driver& { return loader.createDriver(p, c); };
    if (Driver* d = createPlugin<Driver>(decl, create)) {
      Descriptor params = withOverrides(decl, driver_override, index);
      const std::int64_t period = periodOf(decl, driver_override);
      checkPlugin(env, d, params, &a, period, "driver '" + decl.class_name + "'", periodFrom(decl, driver_override),
                  &decl, driver_override);
      a.setDriver(*d, std::move(params), period, decl.class_name);
    }
  }
  for (std::size_t i = 0; i < type->sensors.size(); ++i) {
    const PluginDecl& decl = type->sensors[i];
    auto create = [&](std::string_view p, std::string_view c) -> Sensor& { return loader.createSensor(p, c); };
    if (Sensor* s = createPlugin<Sensor>(decl, create)) {
      Descriptor params = withOverrides(decl, sensor_overrides[i], index);
      const std::int64_t period = periodOf(decl, sensor_overrides[i]);
      checkPlugin(env, s, params, &a, period, "sensor " + std::to_string(i) + " '" + decl.class_name + "'",
                  periodFrom(decl, sensor_overrides[i]), &decl, sensor_overrides[i]);
      a.addSensor(*s, std::move(params), period, decl.class_name);
    }
  }
  if (errorCount() != errors_before) return;  // the class checks assume values of the declared types
  for (std::size_t i = 0; i < a.sensorCount(); ++i)
    validatePlugin(env, &a.sensor(i), a.sensorParameters(i), &a, a.sensor(i).periodSteps(),
                   "sensor " + std::to_string(i) + " '" + a.sensor(i).className() + "'");
  if (a.driver() != nullptr)
    validatePlugin(env, a.driver(), a.driverParameters(), &a, a.driver()->periodSteps(),
                   "driver '" + a.driver()->className() + "'");
}

void SceneLoader::buildObstacle(Environment& env, const Descriptor& d) {
  const std::size_t errors_before = errorCount();
  const std::string name = require(d, "name");
  const Pose pose = readPose(d);
  const auto color = readColor(d, {0.55f, 0.55f, 0.6f, 1.0f});
  PhysicNodeSpec spec;
  spec.name = name;
  spec.where = d.where();
  spec.is_static = true;
  RenderNodeSpec render;
  render.name = name;
  for (const Descriptor& c : d.children()) {
    if (!kShapeElements.contains(c.name())) continue;
    spec.shapes.push_back(readShape(c));
    RenderNodeSpec r = readRenderNode(c, false);
    r.color = color;
    render.children.push_back(std::move(r));
  }
  checkUnknown(d, kShapeElements);
  if (spec.shapes.empty()) error(d.where(), "<obstacle>: needs at least one shape (box, sphere, cylinder, capsule)");
  if (name.empty() || errorCount() != errors_before) return;
  if (env.findArtifact(name) != nullptr) {
    error(d.where(), "duplicate artifact name '" + name + "'");
    return;
  }
  Artifact& a = env.addArtifact(name, pose);
  a.addPhysicRoot(std::move(spec));
  a.addRenderRoot(std::move(render));
}

void SceneLoader::buildSwarm(Environment& env, const Descriptor& d, std::size_t swarm_index) {
  const std::size_t errors_before = errorCount();
  const std::string type = require(d, "type");
  const std::int64_t count = readCount(d, "count", 1, 1);
  const std::string pattern = read<std::string>(d, "name", type + "{i}");
  const std::int64_t first = readCount(d, "first_index", 0, 0);
  const std::string layout = readChoice(d, "layout", "grid", {"grid", "random", "sphere"});
  const Pose origin = readPose(d);
  std::vector<Vec3> positions;
  if (layout == "grid") {
    const double spacing = readPositive(d, "spacing", 1.0);
    const auto columns =
        readCount(d, "columns", static_cast<std::int64_t>(std::ceil(std::sqrt(static_cast<double>(count)))), 1);
    const auto rows = readCount(d, "rows", (count + columns - 1) / columns, 1);
    positions = detail::gridLayout(count, spacing, columns, rows);
  } else if (layout == "random") {
    const Vec3 lo = read<Vec3>(d, "min", Vec3(-1, -1, 0));
    const Vec3 hi = read<Vec3>(d, "max", Vec3(1, 1, 1));
    if (!(lo.array() <= hi.array()).all()) error(d.where(), "<swarm>: every component of 'min' must be <= 'max'");
    const double min_distance = read<double>(d, "min_distance", 0.0);
    // a stream of its own, from the scene seed and the swarm's position among the swarms
    Random rng(deriveSeed(settings_.seed, 0xa11ce5ULL, swarm_index));
    positions = detail::randomLayout(count, lo, hi, min_distance, rng);
    if (static_cast<std::int64_t>(positions.size()) < count) {
      error(d.where(), "<swarm>: could not place " + std::to_string(count) + " members " +
                           std::to_string(min_distance) + " m apart in the box: enlarge it or lower min_distance");
      positions.resize(static_cast<std::size_t>(count), Vec3::Zero());
    }
  } else {
    positions = detail::sphereLayout(count, readPositive(d, "radius", 1.0));
  }
  checkUnknown(d, {"driver", "sensor"});
  if (count > 1 && pattern.find("{i}") == std::string::npos)
    error(d.where(), "<swarm>: the name pattern '" + pattern + "' needs {i} to give " + std::to_string(count) +
                         " artifacts different names");
  if (type.empty() || errorCount() != errors_before) return;
  for (std::int64_t i = 0; i < count; ++i) {
    std::string name = pattern;
    const std::string index = std::to_string(first + i);
    for (auto at = name.find("{i}"); at != std::string::npos; at = name.find("{i}", at + index.size()))
      name.replace(at, 3, index);
    Pose pose = origin;
    pose.position = origin.transformPoint(positions[static_cast<std::size_t>(i)]);
    place(env, name, type, pose, d, index);
    if (errorCount() != errors_before) return;  // one report per swarm, not one per robot
  }
}

}  // namespace ssx::detail
