// The scene builder: a SceneModel into an Environment (see builder.hpp); the plugin checks are in
// plugin_checks.cpp, the robots that start inside one another in start_overlaps.cpp.
#include "scene/builder.hpp"

namespace ssx::detail {

namespace fs = std::filesystem;

namespace {

// how an obstacle's shape looks: the same geometry, in the obstacle's colour
RenderNodeSpec renderNodeOf(const Shape& s, const Color& color) {
  RenderNodeSpec r;
  r.pose = s.pose;
  r.color = color;
  r.size = s.size;
  r.radius = s.radius;
  r.length = s.length;
  switch (s.kind) {
    case Shape::Kind::Box: r.primitive = RenderNodeSpec::Primitive::Box; break;
    case Shape::Kind::Sphere: r.primitive = RenderNodeSpec::Primitive::Sphere; break;
    case Shape::Kind::Cylinder: r.primitive = RenderNodeSpec::Primitive::Cylinder; break;
    case Shape::Kind::Capsule: r.primitive = RenderNodeSpec::Primitive::Capsule; break;
    case Shape::Kind::Plane: r.primitive = RenderNodeSpec::Primitive::Plane; break;
    case Shape::Kind::Mesh:
      r.primitive = RenderNodeSpec::Primitive::Mesh;
      r.mesh = s.mesh;
      break;
  }
  return r;
}

}  // namespace

void SceneBuilder::buildExtensions(Environment& env, const SceneModel& model) {
  for (std::size_t j = 0; j < model.extensions.size(); ++j) {
    log_.stage = extensionStage(j);
    const ExtensionModel& e = model.extensions[j];
    Descriptor params = e.plugin.params;
    try {
      SimulationExtension& ext = env.classLoader().createExtension(e.plugin.plugin, e.plugin.class_name);
      const std::size_t errors_before = errorCount();
      checkPlugin(env, &ext, params, nullptr, 1, "extension '" + e.plugin.class_name + "'");
      env.addExtension(e.name, ext, params);
      // its own checks run once every artifact exists, if its parameters are of the declared types
      if (errorCount() == errors_before)
        extension_checks_.push_back({&ext, params, "extension '" + e.plugin.class_name + "'"});
    } catch (const PluginError& err) {
      error(params.where(), "<extension>: " + std::string(err.what()));
    } catch (const ConfigError& err) {
      error(params.where(), "<extension>: " + err.detail());
    }
  }
}

void SceneBuilder::checkCameras(const SceneModel& model) {
  // what the cameras write, with the plugins' outputs
  for (const CameraSpec& cam : model.settings.render.cameras) {
    const SourceLocation where = cam.where.file.empty() ? SourceLocation{model.file.string(), 0} : cam.where;
    const std::string who = "camera '" + cam.name + "': ";
    if (!cam.snapshot.empty())
      if (auto problem = files_.claimOutput(cam.snapshot, who + "snapshot", false, true); !problem.empty()) error(where, problem);
    if (!cam.video.empty())
      if (auto problem = files_.claimOutput(cam.video, who + "video", false, true); !problem.empty()) error(where, problem);
    if (!cam.frames_dir.empty())
      if (auto problem = files_.claimOutputDirectory(cam.frames_dir, who + "frames"); !problem.empty())
        error(where, problem);
  }
}

void SceneBuilder::checkFollowedNodes(const Environment& env, const SceneModel& model) {
  for (const CameraSpec& cam : model.settings.render.cameras) {
    if (cam.follow.empty()) continue;
    const Artifact* a = env.findArtifact(cam.follow);
    if (a == nullptr || a->rootCount() == 0)
      error(cam.follow_from, "<camera>: follows '" + cam.follow + "', which is no artifact with a physic root in this scene");
  }
}

Scene SceneBuilder::build(const SceneModel& model, bool report_missing_types) {
  Scene scene;
  scene.file = model.file;
  files_.allowSpecialOutputs(options_.allow_special_outputs);
  for (const fs::path& f : model.files) files_.addInput(f);
  scene.run.realtime_factor = model.run.realtime_factor;
  scene.run.overrun = model.run.overrun;
  scene.duration = model.duration;
  try {
    scene.environment = std::make_unique<Environment>(model.settings);
  } catch (const ConfigError& e) {
    // (the reader checks every setting: a model made in code may still hold a bad one)
    const auto given = model.settings_from.lower_bound("environment@");
    error(given != model.settings_from.end() && given->first.starts_with("environment@") ? given->second
                                                                                        : SourceLocation{model.file.string(), 0},
          e.detail());
    // go on with defaults, so that the artifacts are checked too
    scene.environment = std::make_unique<Environment>(EnvironmentSettings{});
  }
  Environment& env = *scene.environment;
  // search order: the scene's directories, the caller's, then the installation's
  for (const auto& dir : model.plugin_dirs) env.classLoader().addSearchDirectory(dir);
  for (const auto& dir : options_.plugin_path) env.classLoader().addSearchDirectory(dir);
  if (options_.search_installed_plugins) env.classLoader().addSearchDirectory(ClassLoader::installedPluginDirectory());
  buildExtensions(env, model);

  std::vector<std::size_t> placement_of;  // per artifact: the placement that made it
  for (std::size_t k = 0; k < model.placements.size(); ++k) {
    const PlacementModel& p = model.placements[k];
    log_.stage = placementStage(k);
    switch (p.kind) {
      case PlacementModel::Kind::Artifact:
      case PlacementModel::Kind::Swarm: {
        const auto type = model.types.find(p.type);
        if (type == model.types.end()) {
          if (report_missing_types) error(p.where, "unknown artifact type '" + p.type + "' (the model has none of that name)");
          if (p.kind == PlacementModel::Kind::Artifact && env.findArtifact(p.name) != nullptr)
            error(p.where, "duplicate artifact name '" + p.name + "'");
          break;
        }
        if (p.kind == PlacementModel::Kind::Artifact)
          place(env, p.name, p, type->second, p.pose());
        else
          buildSwarm(env, p, type->second);
        break;
      }
      case PlacementModel::Kind::Ground:
        if (env.findArtifact("ground") != nullptr)
          error(p.where, "<ground>: an artifact named 'ground' exists already");
        else
          env.addGround(p.xyz.z());
        break;
      case PlacementModel::Kind::Obstacle:
        buildObstacle(env, p);
        break;
    }
    placement_of.resize(env.artifactCount(), k);
  }
  // robots inside one another or an obstacle (checked once every artifact is built as asked)
  // (not after the reader's errors: what it left out of the model would be missing here)
  if (errorCount() == 0 && !order_.after_errors) checkStartOverlaps(env, model, placement_of);
  log_.stage = documentStage(3);
  checkCameras(model);
  // extensions check what they refer to (artifacts by name) once every artifact exists
  for (const auto& c : extension_checks_) validatePlugin(env, c.extension, c.params, nullptr, 1, c.what);
  checkFollowedNodes(env, model);
  scene.files = files_;
  return scene;
}

// --- building ------------------------------------------------------------------------------------

template <class T, class Create>
T* SceneBuilder::createPlugin(const PluginDeclaration& decl, Create create) {
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

bool SceneBuilder::place(Environment& env, const std::string& name, const PlacementModel& p,
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
    const PluginDeclaration& decl = *type.driver;
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
    const PluginDeclaration& decl = type.sensors[i];
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
  if (!p.present) {
    try {
      env.despawn(a);
    } catch (const Error& e) {
      error(p.where, std::string("present=\"false\": ") + e.what());
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

void SceneBuilder::buildObstacle(Environment& env, const PlacementModel& p) {
  if (env.findArtifact(p.name) != nullptr) {
    error(p.where, "duplicate artifact name '" + p.name + "'");
    return;
  }
  PhysicNodeSpec spec;
  spec.name = p.name;
  spec.where = p.where;
  spec.is_static = true;
  RenderNodeSpec look;
  look.name = p.name;
  for (const ShapeModel& m : p.shapes) {
    spec.shapes.push_back(m.shape);
    look.children.push_back(renderNodeOf(m.shape, p.color));
  }
  Artifact& a = env.addArtifact(p.name, p.pose());
  a.addPhysicRoot(std::move(spec));
  a.addRenderRoot(std::move(look));
}

void SceneBuilder::buildSwarm(Environment& env, const PlacementModel& p, const ArtifactTypeModel& type) {
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
