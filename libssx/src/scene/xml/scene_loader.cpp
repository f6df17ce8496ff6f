// Pass 1 of the scene loader: the scene and its includes, the environment, physics, render and wind
// settings; see scene_loader.hpp for the whole.
#include "scene/xml/scene_loader.hpp"
#include "scene/xml/xml_reader.hpp"

#include "engines/engine_options.hpp"
#include "plugin/parameter_checks.hpp"

#include <ssx/scene.hpp>

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <unordered_map>

namespace ssx {

namespace fs = std::filesystem;

namespace detail {

bool SceneLoader::once(const Descriptor& d, const Descriptor*& slot) {
  if (slot != nullptr) {
    error(d.where(), "<" + d.name() + "> given twice (first at " + slot->where().str() + ")");
    return false;
  }
  slot = &d;
  return true;
}

void SceneLoader::noteSettings(const Descriptor& d, const std::string& path) {
  for (const auto& a : d.attributes()) model_.settings_from[path + "@" + a.key] = a.where;
}

void SceneLoader::collect(const Descriptor& scene, const fs::path& dir, std::vector<fs::path>& stack) {
  if (scene.name() != "scene") {
    error(scene.where(), "the root element of a scene file must be <scene>, got <" + scene.name() + ">");
    return;
  }
  for (const Descriptor& d : scene.children()) {
    const std::string& n = d.name();
    if (n == "environment") {
      if (once(d, environment_element_)) {
        readEnvironment(d);
        noteSettings(d, n);
      }
    } else if (n == "physics") {
      if (once(d, physics_element_)) {
        readPhysics(d);
        noteSettings(d, n);
      }
    } else if (n == "render") {
      if (once(d, render_element_)) {
        readRender(d);
        noteSettings(d, n);
      }
    } else if (n == "wind") {
      if (once(d, wind_element_)) {
        readWind(d);
        noteSettings(d, n);
      }
    } else if (n == "plugin_path") {
      const std::string p = require(d, "dir");
      if (!p.empty()) plugin_dirs_.push_back(resolve(dir, p));
      checkUnknown(d);
    } else if (n == "extension") {
      if (options_.extensions) extensions_.push_back({&d, dir});
    } else if (n == "type") {
      const std::string name = require(d, "name");
      const std::string file = d.get<std::string>("file", "");
      checkUnknown(d, {"driver", "sensor", "joint"});
      if (name.empty()) continue;
      if (d.has("file") && file.empty()) {
        error(d.where(), "<type>: attribute 'file' is empty; give an artifact file, or leave 'file' out to use the "
                         "installed type '" + name + "'");
        continue;
      }
      const fs::path path = file.empty() ? findArtifactType(d, name) : resolve(dir, file);
      if (path.empty()) continue;
      TypeDecl decl{path, d.where(), {}, {}};
      for (const Descriptor& c : d.children()) {
        if (c.name() == "driver" || c.name() == "sensor") decl.plugins.push_back(&c);
        if (c.name() == "joint") decl.joints.push_back(&c);
      }
      const auto [it, fresh] = type_decls_.try_emplace(name, std::move(decl));
      if (!fresh)
        error(d.where(),
              "<type>: artifact type '" + name + "' declared twice (first at " + it->second.where.str() + ")");
    } else if (n == "artifact" || n == "swarm" || n == "ground" || n == "obstacle") {
      entities_.push_back({&d, dir});
    } else if (n == "include") {
      const std::string file = require(d, "file");
      checkUnknown(d);
      if (file.empty()) continue;
      const fs::path path = resolve(dir, file);
      std::error_code ec;
      const fs::path canonical = fs::weakly_canonical(path, ec);
      if (std::find(stack.begin(), stack.end(), canonical) != stack.end()) {
        error(d.where(), "<include>: include cycle: '" + file + "' is already being read");
        continue;
      }
      try {
        model_.files.push_back(path);
        documents_.push_back(readXmlFile(path, options_.max_input_bytes));
      } catch (const ConfigError& e) {
        if (e.where().line == 0)
          error(d.where(), "<include>: '" + file + "': " + e.detail());
        else
          record(e);
        continue;
      }
      stack.push_back(canonical);
      collect(documents_.back(), path.parent_path(), stack);
      stack.pop_back();
    }
  }
  checkUnknown(scene, {"environment", "physics", "render", "wind", "plugin_path", "extension", "type", "artifact", "swarm",
                       "ground", "obstacle", "include"});
}

fs::path SceneLoader::findArtifactType(const Descriptor& d, const std::string& name) {
  std::vector<fs::path> dirs = options_.artifact_path;
  if (options_.search_installed_artifacts)
    if (const fs::path data = installedDataDirectory(); !data.empty()) dirs.push_back(data / "artifacts");
  const bool plain = name.find('/') == std::string::npos && name != "." && name != "..";
  std::string looked;
  for (const fs::path& dir : dirs) {
    std::error_code ec;
    const fs::path candidate = dir / (name + ".xml");
    if (plain && fs::is_regular_file(candidate, ec)) return candidate;
    looked += (looked.empty() ? "" : ", ") + dir.string();
  }
  error(d.where(), "<type>: no 'file' given and no installed artifact type '" + name + "' (looked for " + name +
                       ".xml in " + (looked.empty() ? std::string("no directory") : looked) +
                       "); give file=\"path/to/" + name + ".xml\" relative to this scene");
  return {};
}

void SceneLoader::readEnvironment(const Descriptor& d) {
  settings_.timestep = toNanoseconds(readPositiveAtMost(d, "timestep", toSeconds(settings_.timestep), kMaxTimestepSeconds,
                                                       "a step of the physics, in seconds"));
  if (settings_.timestep <= 0) {
    error(d.where(), "<environment>: timestep is below one nanosecond");
    settings_.timestep = EnvironmentSettings{}.timestep;  // reported once, here
  } else if (const auto* given = d.find("timestep")) {
    // time is counted in whole nanoseconds: say what a finer timestep became
    double asked = static_cast<double>(settings_.timestep);
    try {
      asked = d.get<double>("timestep") * 1e9;
    } catch (const ConfigError&) {
      // (reported above)
    }
    // (a timestep refused above was reported; it is no rounding)
    const bool accepted = asked > 0 && asked <= kMaxTimestepSeconds * 1e9;
    if (accepted && std::abs(asked - static_cast<double>(settings_.timestep)) > 1e-3)
      warning(given->where, "<environment>: timestep " + given->value + " s is " + std::to_string(settings_.timestep) +
                                " ns (time is counted in whole nanoseconds)");
  }
  if (const auto* given = d.find("seed")) {
    if (const auto seed = parseSeed(given->value))
      settings_.seed = *seed;
    else
      error(given->where, "<environment>: attribute 'seed' must be a whole number from 0 to " + std::to_string(kMaxSeed) +
                              ", got '" + given->value + "'");
  }
  const std::string threads = read<std::string>(d, "threads", "auto");
  if (threads != "auto") {
    std::int64_t n = 0;
    try {
      n = d.get<std::int64_t>("threads");
    } catch (const ConfigError&) {
      n = 0;  // reported below, with the accepted forms
    }
    if (n < 1 || n > 1024)
      record(d.error(*d.find("threads"),
                     "attribute 'threads' must be 'auto' or a whole number from 1 to 1024, got '" + threads + "'"));
    else
      settings_.threads = static_cast<int>(n);
  }
  run_.realtime_factor = readPositiveAtMost(d, "realtime_factor", 1.0, kMaxRealtimeFactor, "times real time");
  if (run_.realtime_factor < kMinRealtimeFactor)
    record(d.error(*d.find("realtime_factor"), "attribute 'realtime_factor' must be at least 0.001 (a thousand "
                                               "times slower than real time), got '" +
                                                   d.find("realtime_factor")->value + "'"));
  run_.overrun = readChoice(d, "overrun", "catchup", {"catchup", "resync"}) == "resync" ? RunOptions::Overrun::Resync
                                                                                        : RunOptions::Overrun::CatchUp;
  asked(d, "duration");  // (read only when given: still a name an unknown attribute may have meant)
  if (d.has("duration")) {
    duration_ = toNanoseconds(readPositiveAtMost(d, "duration", 1.0, kMaxDurationSeconds, "about 31 years of simulated time"));
    if (*duration_ <= 0) {
      error(d.find("duration")->where, "<environment>: duration is shorter than a nanosecond (the run would have no end)");
      duration_ = toNanoseconds(1.0);  // reported once, here
    }
  }
  checkUnknown(d);
}

void SceneLoader::readPhysics(const Descriptor& d) {
  PhysicsSettings& p = settings_.physics;
  const std::vector<std::string> engines = physicEngineNames();
  p.engine = read<std::string>(d, "engine", p.engine);
  if (std::find(engines.begin(), engines.end(), p.engine) == engines.end()) {
    std::string list;
    for (const auto& n : engines) list += (list.empty() ? "" : ", ") + n;
    record(d.error(*d.find("engine"), "attribute 'engine' must be one of " + list + ", got '" + p.engine + "'"));
    p.engine = "ode";
  }
  const bool overridden = options_.physics_engine.has_value();
  if (overridden) p.engine = *options_.physics_engine;
  const PhysicEngineClass* own = findPhysicEngine(p.engine);
  // an attribute that only another engine takes is an error: it would silently do nothing
  std::set<std::string_view> reported;  // (two other engines may declare one name)
  for (const auto& engine : engines) {
    const PhysicEngineClass* other = findPhysicEngine(engine);
    if (other == own || other == nullptr) continue;
    for (const ssx_plugin_param& s : other->settings) {
      if ((own != nullptr && declares(own->settings, s.name)) || !d.has(s.name) || !reported.insert(s.name).second) continue;
      const auto* attr = d.find(s.name);
      error(attr->where, "<physics>: attribute '" + std::string(s.name) + "' is an option of the " + engine +
                             " engine, and the engine is '" + p.engine + "'" + (overridden ? " (chosen with --physics)" : "") +
                             ": remove it, or choose engine=\"" + engine + "\"");
    }
  }
  p.substeps = static_cast<int>(readCount(d, "substeps", p.substeps, 1, 10'000));
  p.gravity = read<Vec3>(d, "gravity", p.gravity);
  // ODE's broadphases were replaced by ssx's grid (linear in the bodies, parallel)
  for (const char* gone : {"broadphase", "quadtree_center", "quadtree_extents", "quadtree_depth"})
    if (d.has(gone))
      error(d.where(), std::string("<physics>: attribute '") + gone +
                               "' is no longer offered: ssx finds contacts with its own grid broadphase "
                               "(linear in the bodies however they are laid out, run in parallel); remove it");
  p.friction = read<double>(d, "friction", p.friction);
  if (p.friction < 0) error(d.where(), "<physics>: friction must not be negative");
  p.restitution = read<double>(d, "restitution", p.restitution);
  if (p.restitution < 0 || p.restitution > 1) error(d.where(), "<physics>: restitution must be in 0..1");
  p.max_linear_speed = readPositive(d, "max_linear_speed", p.max_linear_speed);
  p.max_angular_speed = readPositive(d, "max_angular_speed", p.max_angular_speed);
  // the engine's own settings, checked against its declarations as a plugin's parameters are
  if (own != nullptr) {
    for (const ssx_plugin_param& s : own->settings) {
      asked(d, s.name);
      if (const auto* a = d.find(s.name)) a->used = true;
    }
    std::vector<Diagnostic> found;
    p.options = engineOptions(*own, d, found);
    if (found.empty() && own->configure) own->configure(p.options, p);
    for (auto& problem : found) add(std::move(problem));
  }
  checkUnknown(d);
}

void SceneLoader::readWind(const Descriptor& d) {
  WindSettings& w = settings_.wind;
  w.mean = read<Vec3>(d, "mean", w.mean);
  w.gust = read<Vec3>(d, "gust", w.gust);
  w.gust_start = read<double>(d, "gust_start", w.gust_start);
  w.gust_duration = read<double>(d, "gust_duration", w.gust_duration);
  w.turbulence_w20 = read<double>(d, "turbulence_w20", w.turbulence_w20);
  w.turbulence_min_airspeed = read<double>(d, "turbulence_min_airspeed", w.turbulence_min_airspeed);
  const auto where = [&](const char* a) { return d.has(a) ? d.find(a)->where : d.where(); };
  if (!(w.gust_start >= 0)) error(where("gust_start"), "<wind>: gust_start must not be negative (s)");
  if (!(w.gust_duration > 0)) error(where("gust_duration"), "<wind>: gust_duration must be positive (s)");
  if (!(w.turbulence_w20 >= 0 && w.turbulence_w20 <= 50))
    error(where("turbulence_w20"), "<wind>: turbulence_w20 must be in 0..50 m/s (light 7.7, moderate 15.4)");
  if (!(w.turbulence_min_airspeed > 0))
    error(where("turbulence_min_airspeed"), "<wind>: turbulence_min_airspeed must be positive (m/s)");
  checkUnknown(d);
}

void SceneLoader::readRender(const Descriptor& d) {
  RenderSettings& r = settings_.render;
  render_engine_named_ = d.has("engine");
  r.engine = readChoice(d, "engine", r.engine, {"null", "osmesa"});
  const auto names = renderEngineNames();
  if (std::find(names.begin(), names.end(), r.engine) == names.end()) {
    error(d.find("engine")->where, "render engine '" + r.engine +
                                       "' is not in this build of ssx: install libosmesa6-dev and rebuild");
    r.engine = "null";
  }
  r.period_steps = readCount(d, "period", 0, 0);
  r.rate_hz = read<double>(d, "rate_hz", 0.0);
  if (!(r.rate_hz == 0 || r.rate_hz >= kMinRateHz)) {
    error(d.find("rate_hz")->where, "<render>: rate_hz must be 0 (no frames) or at least 1e-6");
    r.rate_hz = 0;  // reported once, here
  }
  r.width = static_cast<int>(readCount(d, "width", r.width, 1, kMaxImageSide));
  r.height = static_cast<int>(readCount(d, "height", r.height, 1, kMaxImageSide));
  r.background = readColor(d, r.background, "background");
  r.shadows = read<bool>(d, "shadows", r.shadows);
  r.time_stamp = read<bool>(d, "time_stamp", r.time_stamp);
  for (const Descriptor* c : d.childrenNamed("camera")) {
    CameraSpec cam;
    cam.name = read<std::string>(*c, "name", "camera" + std::to_string(r.cameras.size()));
    for (const auto& other : r.cameras)
      if (other.name == cam.name) error(c->where(), "<camera>: duplicate camera name '" + cam.name + "'");
    cam.frame_scene = !c->has("xyz");
    cam.position = read<Vec3>(*c, "xyz", cam.position);
    cam.look_at = read<Vec3>(*c, "look_at", cam.look_at);
    cam.follow = read<std::string>(*c, "follow", "");
    if (!cam.follow.empty()) cam.follow_from = c->find("follow")->where;
    cam.where = c->where();
    cam.fov_deg = read<double>(*c, "fov_deg", cam.fov_deg);
    if (!validFieldOfView(cam.fov_deg)) {
      error(c->find("fov_deg")->where, "<camera>: fov_deg must be in (0, 180)");
      cam.fov_deg = 60;  // reported once, here
    }
    cam.frames_dir = read<std::string>(*c, "frames", "");
    cam.video = read<std::string>(*c, "video", "");
    cam.snapshot = read<std::string>(*c, "snapshot", "");
    // (relative outputs go into the run's output directory, when it has one: see below)
    checkUnknown(*c);
    if (!options_.output_directory.empty())
      for (fs::path* out : {&cam.snapshot, &cam.video, &cam.frames_dir})
        if (!out->empty() && out->is_relative()) *out = options_.output_directory / *out;
    noteSettings(*c, "render/camera[name=" + cam.name + "]");
    r.cameras.push_back(std::move(cam));
  }
  checkUnknown(d, {"camera"});
}

void SceneLoader::applyOptions() {
  if (options_.seed) settings_.seed = *options_.seed;
  if (options_.threads) settings_.threads = *options_.threads;
  if (options_.render_engine) {
    // checked with the scene's own values, before anything is made or opened
    const auto names = renderEngineNames();
    if (std::find(names.begin(), names.end(), *options_.render_engine) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      error({model_.file.string(), 0}, "render engine '" + *options_.render_engine + "' (asked for besides the scene) "
                                       "is not in this build of ssx (available: " + list + ")");
    } else {
      settings_.render.engine = *options_.render_engine;
    }
  }
  if (options_.physics_engine) settings_.physics.engine = *options_.physics_engine;
  // outputs asked for on the command line go to the first camera (one framing the scene if none)
  if (!options_.snapshot.empty() || !options_.video.empty() || !options_.frames_dir.empty()) {
    auto& cameras = settings_.render.cameras;
    if (cameras.empty()) {
      CameraSpec c;
      c.frame_scene = true;
      cameras.push_back(c);
    }
    if (!options_.snapshot.empty()) cameras.front().snapshot = options_.snapshot;
    if (!options_.video.empty()) cameras.front().video = options_.video;
    if (!options_.frames_dir.empty()) cameras.front().frames_dir = options_.frames_dir;
  }
  // pictures asked for (a camera's snapshot, video or frames, in the scene or on the command line)
  // need an engine that draws: when none was named, the osmesa renderer is switched on for them
  RenderSettings& r = settings_.render;
  const bool pictures = std::any_of(r.cameras.begin(), r.cameras.end(), [](const CameraSpec& c) {
    return !c.snapshot.empty() || !c.video.empty() || !c.frames_dir.empty();
  });
  if (pictures && r.engine == "null" && !render_engine_named_ && !options_.render_engine) {
    const auto names = renderEngineNames();
    if (std::find(names.begin(), names.end(), "osmesa") != names.end())
      r.engine = "osmesa";
    else
      error({model_.file.string(), 0}, "a picture was asked for (snapshot, video or frames), and this build of ssx "
                                       "draws none: install libosmesa6-dev and rebuild");
  }
}

void SceneLoader::readExtensions() {
  for (std::size_t j = 0; j < extensions_.size(); ++j) {
    log_.stage = stage(1, 2 * static_cast<std::int64_t>(j));
    const Descriptor& d = *extensions_[j].element;
    const std::string name = require(d, "name");
    std::optional<PluginDecl> decl = readPluginDecl(d);
    if (name.empty() || !decl) continue;
    decl->params.erase("name");  // the extension's name, read here
    model_.extensions.push_back({name, std::move(*decl)});
    extension_stage_.push_back(log_.stage);
  }
}

SceneModel SceneLoader::parse(Descriptor root, const fs::path& file, const fs::path& dir) {
  model_.file = file;
  std::error_code file_ec;
  if (fs::is_regular_file(file, file_ec)) model_.files.push_back(file);  // (a scene in memory is no file)
  log_.stage = stage(0);
  // an override that does not fit is reported with the rest (the scene is read without it)
  // two overrides of one attribute, however spelled, would apply one and report both: refused
  std::map<std::string, const AttributeOverride*> applied;
  for (const auto& o : options_.overrides) {
    std::string identity;
    if (auto problem = applyOverride(root, o, &identity)) {
      error(o.where, *problem);
    } else if (const auto [it, fresh] = applied.emplace(identity, &o); !fresh) {
      error(o.where, "target '" + o.target + "' sets the attribute that target '" + it->second->target + "' (" +
                         it->second->where.str() + ") sets: give each attribute one override");
    }
  }
  documents_.push_back(std::move(root));
  std::error_code ec;
  std::vector<fs::path> stack{fs::weakly_canonical(file, ec)};
  collect(documents_.front(), dir, stack);
  applyOptions();
  readExtensions();
  readPlacements();
  for (const auto& [name, type] : types_)
    if (type.ok) model_.types.emplace(name, static_cast<const ArtifactTypeModel&>(type));
  return std::move(model_);
}

}  // namespace detail

}  // namespace ssx
