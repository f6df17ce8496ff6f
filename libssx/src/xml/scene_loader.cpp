// Scene and artifact files into an Environment. Two passes: collect every element of the scene
// and its includes (checking what can be checked alone), then build the environment, loading
// plugins and artifact types. Every problem is collected; any error stops the load before
// anything starts.
#include "xml/xml_reader.hpp"

#include <ssx/plugin_abi.hpp>
#include <ssx/scene.hpp>

#include <cmath>
#include <deque>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <unordered_map>

namespace ssx {

namespace fs = std::filesystem;

namespace {

std::string joinDiagnostics(const std::vector<Diagnostic>& diagnostics) {
  std::string out;
  std::size_t errors = 0;
  for (const auto& d : diagnostics) {
    if (d.severity == Diagnostic::Severity::Error) ++errors;
    out += (out.empty() ? "" : "\n") + d.str();
  }
  return out + "\n" + std::to_string(errors) + " error(s); nothing was run";
}

}  // namespace

SceneError::SceneError(std::vector<Diagnostic> diagnostics)
    : Error(joinDiagnostics(diagnostics)), diagnostics_(std::move(diagnostics)) {}

namespace {

struct PluginDecl {
  std::string plugin;
  std::string class_name;
  std::int64_t period = 1;
  SourceLocation period_from;  // where `period` was given, if it was
  Descriptor params;
};

struct ArtifactType {
  bool ok = true;
  std::vector<PhysicNodeSpec> physic;
  std::vector<RenderNodeSpec> render;
  std::optional<PluginDecl> driver;
  std::vector<PluginDecl> sensors;
};

// one element of the scene that makes artifacts, in document order
struct Entity {
  const Descriptor* element;
  fs::path dir;  // of the file it came from
};

// the most artifacts one swarm may make, and the bound on other counts
constexpr std::int64_t kMaxCount = 10'000'000;

// the names a file may use for primitive shapes
const std::set<std::string> kShapeElements{"box", "sphere", "cylinder", "capsule"};

class SceneLoader {
 public:
  explicit SceneLoader(const SceneOptions& options) : options_(options) {}

  Scene load(Descriptor root, const fs::path& file, const fs::path& dir);

 private:
  // --- diagnostics ---
  void error(const SourceLocation& where, std::string message) {
    diagnostics_.push_back({Diagnostic::Severity::Error, where, std::move(message)});
  }
  void warning(const SourceLocation& where, std::string message) {
    diagnostics_.push_back({Diagnostic::Severity::Warning, where, std::move(message)});
  }
  void record(const ConfigError& e) { error(e.where(), e.detail()); }
  std::size_t errorCount() const {
    std::size_t n = 0;
    for (const auto& d : diagnostics_) n += d.severity == Diagnostic::Severity::Error ? 1 : 0;
    return n;
  }
  bool hasErrors() const { return errorCount() > 0; }

  // --- typed reads that record errors and fall back ---
  template <class T>
  T read(const Descriptor& d, std::string_view key, const T& fallback) {
    try {
      return d.get<T>(key, fallback);
    } catch (const ConfigError& e) {
      record(e);
      return fallback;
    }
  }
  template <class T>
  std::optional<T> readOptional(const Descriptor& d, std::string_view key) {
    if (!d.has(key)) return std::nullopt;
    try {
      return d.get<T>(key);
    } catch (const ConfigError& e) {
      record(e);
      return std::nullopt;
    }
  }
  std::string require(const Descriptor& d, std::string_view key) {
    if (!d.has(key)) {
      error(d.where(), "<" + d.name() + ">: missing attribute '" + std::string(key) + "'");
      return {};
    }
    return d.get<std::string>(key);
  }
  double readPositive(const Descriptor& d, std::string_view key, double fallback) {
    try {
      return d.getPositive(key, fallback);
    } catch (const ConfigError& e) {
      record(e);
      return fallback;
    }
  }
  // a whole number in [min, max]; the upper bounds keep absurd input from allocating the machine away
  std::int64_t readCount(const Descriptor& d, std::string_view key, std::int64_t fallback, std::int64_t min,
                         std::int64_t max = kMaxCount) {
    const std::int64_t v = read<std::int64_t>(d, key, fallback);
    if (v < min || v > max) {
      const auto* a = d.find(key);
      const std::string message = "attribute '" + std::string(key) + "' must be " +
                                  (v < min ? "at least " + std::to_string(min) : "at most " + std::to_string(max)) +
                                  ", got " + std::to_string(v);
      record(a != nullptr ? d.error(*a, message) : d.error(message));
      return fallback;
    }
    return v;
  }
  // one of a set of words
  std::string readChoice(const Descriptor& d, std::string_view key, const std::string& fallback,
                         std::initializer_list<const char*> choices) {
    const std::string v = read<std::string>(d, key, fallback);
    std::string list;
    for (const char* c : choices) {
      if (v == c) return v;
      list += std::string(list.empty() ? "" : ", ") + c;
    }
    const auto* a = d.find(key);
    record(d.error(*a, "attribute '" + std::string(key) + "' must be one of " + list + ", got '" + v + "'"));
    return fallback;
  }
  Pose readPose(const Descriptor& d) {
    Pose p;
    p.position = read<Vec3>(d, "xyz", Vec3::Zero());
    const Vec3 rpy = read<Vec3>(d, "rpy", Vec3::Zero());
    // fixed-axis roll, pitch, yaw (as URDF): R = Rz(yaw) Ry(pitch) Rx(roll)
    p.orientation = Quat(Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                         Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()));
    return p;
  }
  std::array<float, 4> readColor(const Descriptor& d, std::array<float, 4> fallback, const char* key = "color") {
    const auto* a = d.find(key);
    if (a == nullptr) return fallback;
    std::istringstream in(a->value);
    std::vector<double> v;
    double x;
    while (in >> x) v.push_back(x);
    const bool ok = in.eof() && (v.size() == 3 || v.size() == 4) &&
                    std::all_of(v.begin(), v.end(), [](double c) { return c >= 0 && c <= 1; });
    if (!ok) {
      record(d.error(*a, "attribute '" + std::string(key) + "' must be \"r g b\" or \"r g b a\" with each in 0..1, got '" +
                             a->value + "'"));
      return fallback;
    }
    return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]),
            static_cast<float>(v.size() == 4 ? v[3] : 1.0)};
  }
  // unknown attributes (those nobody read) and unknown child elements are warnings
  void checkUnknown(const Descriptor& d, const std::set<std::string>& children = {}) {
    for (const auto& a : d.attributes())
      if (!a.used) warning(a.where, "unknown attribute '" + a.key + "' of <" + d.name() + "> (ignored)");
    for (const auto& c : d.children())
      if (!children.contains(c.name()))
        warning(c.where(), "unknown element <" + c.name() + "> in <" + d.name() + "> (ignored)");
  }
  fs::path resolve(const fs::path& dir, const std::string& file) const {
    const fs::path p(file);
    return p.is_absolute() ? p : dir / p;
  }

  // --- pass 1: the scene and its includes ---
  void collect(const Descriptor& scene, const fs::path& dir, std::vector<fs::path>& stack);
  void readEnvironment(const Descriptor& d);
  void readPhysics(const Descriptor& d);
  void readRender(const Descriptor& d);
  bool once(const Descriptor& d, const Descriptor*& slot);

  // --- artifact files ---
  const ArtifactType* artifactType(const std::string& name, const SourceLocation& where);
  ArtifactType parseArtifact(const Descriptor& root);
  Shape readShape(const Descriptor& d);
  PhysicNodeSpec readPhysicNode(const Descriptor& d);
  RenderNodeSpec readRenderNode(const Descriptor& d, bool is_root);
  std::optional<PluginDecl> readPluginDecl(const Descriptor& d);

  // --- pass 2: build ---
  void build(Scene& scene);
  void buildObstacle(Environment& env, const Descriptor& d);
  void buildSwarm(Environment& env, const Descriptor& d, std::size_t swarm_index);
  void place(Environment& env, const std::string& name, const std::string& type, const Pose& pose,
             const Descriptor& element, const std::string& index = {});
  Descriptor withOverrides(const PluginDecl& decl, const Descriptor* overrides, const std::string& index);
  std::int64_t periodOf(const PluginDecl& decl, const Descriptor* overrides);
  static SourceLocation periodFrom(const PluginDecl& decl, const Descriptor* overrides);
  template <class T, class Create>
  T* createPlugin(const PluginDecl& decl, Create create);
  // checks a plugin's parameters against its class's declarations (defaults added)
  void checkPlugin(Environment& env, const void* instance, Descriptor& params, const Artifact* artifact,
                   std::int64_t period_steps, const std::string& what, const SourceLocation& period_from = {});
  // runs a class's own validate on a parameter set that passed checkPlugin
  void validatePlugin(Environment& env, const void* instance, const Descriptor& params, const Artifact* artifact,
                      std::int64_t period_steps, const std::string& what);

  const SceneOptions& options_;
  std::vector<Diagnostic> diagnostics_;
  std::deque<Descriptor> documents_;  // every file read, kept alive for the pointers below
  EnvironmentSettings settings_;
  RunOptions run_;
  std::optional<Nanoseconds> duration_;
  const Descriptor* environment_element_ = nullptr;
  const Descriptor* physics_element_ = nullptr;
  const Descriptor* render_element_ = nullptr;
  std::vector<fs::path> plugin_dirs_;
  std::vector<Entity> extensions_;
  std::vector<Entity> entities_;
  struct TypeDecl {
    fs::path file;
    SourceLocation where;
  };
  std::map<std::string, TypeDecl> type_decls_;
  std::map<std::string, ArtifactType> types_;          // by type name, parsed on first use
  std::map<std::string, std::string> failed_plugins_;  // "plugin/class" -> already reported
  std::vector<std::pair<std::string, SourceLocation>> camera_follows_;  // checked once artifacts exist
  struct ExtensionCheck {
    const SimulationExtension* extension;
    Descriptor params;
    std::string what;
  };
  std::vector<ExtensionCheck> extension_checks_;
};

bool SceneLoader::once(const Descriptor& d, const Descriptor*& slot) {
  if (slot != nullptr) {
    error(d.where(), "<" + d.name() + "> given twice (first at " + slot->where().str() + ")");
    return false;
  }
  slot = &d;
  return true;
}

void SceneLoader::collect(const Descriptor& scene, const fs::path& dir, std::vector<fs::path>& stack) {
  if (scene.name() != "scene") {
    error(scene.where(), "the root element of a scene file must be <scene>, got <" + scene.name() + ">");
    return;
  }
  for (const Descriptor& d : scene.children()) {
    const std::string& n = d.name();
    if (n == "environment") {
      if (once(d, environment_element_)) readEnvironment(d);
    } else if (n == "physics") {
      if (once(d, physics_element_)) readPhysics(d);
    } else if (n == "render") {
      if (once(d, render_element_)) readRender(d);
    } else if (n == "plugin_path") {
      const std::string p = require(d, "dir");
      if (!p.empty()) plugin_dirs_.push_back(resolve(dir, p));
      checkUnknown(d);
    } else if (n == "extension") {
      extensions_.push_back({&d, dir});
    } else if (n == "type") {
      const std::string name = require(d, "name");
      const std::string file = require(d, "file");
      checkUnknown(d);
      if (name.empty() || file.empty()) continue;
      const auto [it, fresh] = type_decls_.try_emplace(name, TypeDecl{resolve(dir, file), d.where()});
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
        documents_.push_back(detail::readXmlFile(path));
      } catch (const ConfigError& e) {
        if (e.where().line == 0)
          error(d.where(), "<include>: cannot read '" + path.string() + "' (missing, a directory, or no permission)");
        else
          record(e);
        continue;
      }
      stack.push_back(canonical);
      collect(documents_.back(), path.parent_path(), stack);
      stack.pop_back();
    }
  }
  checkUnknown(scene, {"environment", "physics", "render", "plugin_path", "extension", "type", "artifact", "swarm",
                       "ground", "obstacle", "include"});
}

void SceneLoader::readEnvironment(const Descriptor& d) {
  settings_.timestep = toNanoseconds(readPositive(d, "timestep", toSeconds(settings_.timestep)));
  if (settings_.timestep <= 0) error(d.where(), "<environment>: timestep is below one nanosecond");
  const std::int64_t seed = readCount(d, "seed", 0, 0);
  settings_.seed = static_cast<std::uint64_t>(seed);
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
  run_.realtime_factor = readPositive(d, "realtime_factor", 1.0);
  run_.overrun = readChoice(d, "overrun", "catchup", {"catchup", "resync"}) == "resync" ? RunOptions::Overrun::Resync
                                                                                        : RunOptions::Overrun::CatchUp;
  if (d.has("duration")) duration_ = toNanoseconds(readPositive(d, "duration", 1.0));
  checkUnknown(d);
}

void SceneLoader::readPhysics(const Descriptor& d) {
  PhysicsSettings& p = settings_.physics;
  p.engine = readChoice(d, "engine", p.engine, {"ode"});
  p.solver = readChoice(d, "solver", "quickstep", {"quickstep", "exact"}) == "exact"
                 ? PhysicsSettings::Solver::Exact
                 : PhysicsSettings::Solver::QuickStep;
  p.iterations = static_cast<int>(readCount(d, "iterations", p.iterations, 1, 100'000));
  p.sor = readPositive(d, "sor", p.sor);
  p.substeps = static_cast<int>(readCount(d, "substeps", p.substeps, 1, 10'000));
  p.gravity = read<Vec3>(d, "gravity", p.gravity);
  p.erp = readPositive(d, "erp", p.erp);
  p.cfm = readPositive(d, "cfm", p.cfm);
  p.broadphase = readChoice(d, "broadphase", "sap", {"sap", "quadtree"}) == "quadtree"
                     ? PhysicsSettings::Broadphase::QuadTree
                     : PhysicsSettings::Broadphase::SweepAndPrune;
  p.quadtree_center = read<Vec3>(d, "quadtree_center", p.quadtree_center);
  p.quadtree_extents = read<Vec3>(d, "quadtree_extents", p.quadtree_extents);
  p.quadtree_depth = static_cast<int>(readCount(d, "quadtree_depth", p.quadtree_depth, 1, 12));
  p.friction = read<double>(d, "friction", p.friction);
  if (p.friction < 0) error(d.where(), "<physics>: friction must not be negative");
  p.restitution = read<double>(d, "restitution", p.restitution);
  if (p.restitution < 0 || p.restitution > 1) error(d.where(), "<physics>: restitution must be in 0..1");
  p.max_contacts = static_cast<int>(readCount(d, "max_contacts", p.max_contacts, 1, 1024));
  p.contact_surface_layer = read<double>(d, "contact_surface_layer", p.contact_surface_layer);
  p.max_linear_speed = readPositive(d, "max_linear_speed", p.max_linear_speed);
  p.max_angular_speed = readPositive(d, "max_angular_speed", p.max_angular_speed);
  checkUnknown(d);
}

void SceneLoader::readRender(const Descriptor& d) {
  RenderSettings& r = settings_.render;
  r.engine = readChoice(d, "engine", r.engine, {"null", "osmesa"});
  const auto names = renderEngineNames();
  if (std::find(names.begin(), names.end(), r.engine) == names.end()) {
    error(d.find("engine")->where, "render engine '" + r.engine +
                                       "' is not in this build of ssx: install libosmesa6-dev and rebuild");
    r.engine = "null";
  }
  r.period_steps = readCount(d, "period", 0, 0);
  r.rate_hz = read<double>(d, "rate_hz", 0.0);
  if (!(r.rate_hz >= 0)) error(d.find("rate_hz")->where, "<render>: rate_hz must be 0 or positive");
  r.width = static_cast<int>(readCount(d, "width", r.width, 1, kMaxImageSide));
  r.height = static_cast<int>(readCount(d, "height", r.height, 1, kMaxImageSide));
  r.background = readColor(d, r.background, "background");
  for (const Descriptor* c : d.childrenNamed("camera")) {
    CameraSpec cam;
    cam.name = read<std::string>(*c, "name", "camera" + std::to_string(r.cameras.size()));
    for (const auto& other : r.cameras)
      if (other.name == cam.name) error(c->where(), "<camera>: duplicate camera name '" + cam.name + "'");
    cam.frame_scene = !c->has("xyz");
    cam.position = read<Vec3>(*c, "xyz", cam.position);
    cam.look_at = read<Vec3>(*c, "look_at", cam.look_at);
    cam.follow = read<std::string>(*c, "follow", "");
    if (!cam.follow.empty()) camera_follows_.push_back({cam.follow, c->find("follow")->where});
    cam.fov_deg = read<double>(*c, "fov_deg", cam.fov_deg);
    if (!validFieldOfView(cam.fov_deg)) {
      error(c->find("fov_deg")->where, "<camera>: fov_deg must be in (0, 180)");
      cam.fov_deg = 60;  // reported once, here
    }
    cam.frames_dir = read<std::string>(*c, "frames", "");
    cam.video = read<std::string>(*c, "video", "");
    cam.snapshot = read<std::string>(*c, "snapshot", "");
    checkUnknown(*c);
    r.cameras.push_back(std::move(cam));
  }
  checkUnknown(d, {"camera"});
}

// --- artifact files ------------------------------------------------------------------------------

Shape SceneLoader::readShape(const Descriptor& d) {
  Shape s;
  const std::string& n = d.name();
  if (n == "box") {
    s = Shape::box(read<Vec3>(d, "size", Vec3::Ones()));
    if (!d.has("size")) error(d.where(), "<box>: missing attribute 'size'");
  } else if (n == "sphere") {
    s = Shape::sphere(readPositive(d, "radius", 0.5));
  } else {
    const double r = readPositive(d, "radius", 0.5);
    const double l = n == "cylinder" ? readPositive(d, "length", 1.0) : read<double>(d, "length", 0.0);
    s = n == "cylinder" ? Shape::cylinder(r, l) : Shape::capsule(r, l);
    if (n == "capsule" && l < 0) error(d.where(), "<capsule>: length must not be negative");
  }
  if (n == "box" && !(s.size.array() > 0).all()) error(d.where(), "<box>: every size must be positive");
  s.pose = readPose(d);
  s.density = readPositive(d, "density", s.density);
  checkUnknown(d);
  return s;
}

PhysicNodeSpec SceneLoader::readPhysicNode(const Descriptor& d) {
  PhysicNodeSpec n;
  n.where = d.where();
  n.name = read<std::string>(d, "name", "");
  n.pose = readPose(d);
  n.mass = readOptional<double>(d, "mass");
  if (auto diag = readOptional<Vec3>(d, "inertia")) {
    Mat3 j = diag->asDiagonal();
    const Vec3 products = read<Vec3>(d, "inertia_products", Vec3::Zero());  // ixy ixz iyz
    j(0, 1) = j(1, 0) = products.x();
    j(0, 2) = j(2, 0) = products.y();
    j(1, 2) = j(2, 1) = products.z();
    n.inertia = j;
  }
  n.center_of_mass = read<Vec3>(d, "com", Vec3::Zero());
  n.is_static = read<bool>(d, "static", false);  // validatePhysicTree refuses it below the root
  for (const Descriptor& c : d.children()) {
    if (kShapeElements.contains(c.name()))
      n.shapes.push_back(readShape(c));
    else if (c.name() == "physic")
      n.children.push_back(readPhysicNode(c));
  }
  std::set<std::string> allowed = kShapeElements;
  allowed.insert("physic");
  checkUnknown(d, allowed);
  return n;
}

RenderNodeSpec SceneLoader::readRenderNode(const Descriptor& d, bool is_root) {
  RenderNodeSpec n;
  n.name = read<std::string>(d, "name", "");
  n.pose = readPose(d);
  n.color = readColor(d, n.color);
  if (is_root) n.follow = read<std::string>(d, "follow", "");
  const std::string& kind = d.name();
  if (kind == "box") {
    n.primitive = RenderNodeSpec::Primitive::Box;
    n.size = read<Vec3>(d, "size", Vec3::Ones());
  } else if (kind == "sphere") {
    n.primitive = RenderNodeSpec::Primitive::Sphere;
    n.radius = readPositive(d, "radius", 0.5);
  } else if (kind == "cylinder" || kind == "capsule") {
    n.primitive = kind == "cylinder" ? RenderNodeSpec::Primitive::Cylinder : RenderNodeSpec::Primitive::Capsule;
    n.radius = readPositive(d, "radius", 0.5);
    n.length = readPositive(d, "length", 1.0);
  } else if (kind == "plane") {
    n.primitive = RenderNodeSpec::Primitive::Plane;
    n.size = read<Vec3>(d, "size", Vec3(10, 10, 0));
  }
  for (const Descriptor& c : d.children())
    if (kShapeElements.contains(c.name()) || c.name() == "plane" || c.name() == "render")
      n.children.push_back(readRenderNode(c, false));
  std::set<std::string> allowed = kShapeElements;
  allowed.insert({"plane", "render"});
  checkUnknown(d, allowed);
  return n;
}

std::optional<PluginDecl> SceneLoader::readPluginDecl(const Descriptor& d) {
  PluginDecl decl;
  decl.plugin = require(d, "plugin");
  decl.class_name = read<std::string>(d, "class", decl.plugin);
  decl.period = readCount(d, "period", 1, 1);
  if (const auto* a = d.find("period")) decl.period_from = a->where;
  // the element is the parameter set, without what the loader itself reads: a plugin never
  // mistakes its period in steps for a parameter of its own (periodSteps() tells it)
  decl.params = d;
  decl.params.erase("plugin").erase("class").erase("period");
  // a plugin's own parameters are checked when it is configured; element children are not allowed
  for (const auto& c : d.children())
    warning(c.where(), "unknown element <" + c.name() + "> in <" + d.name() + "> (ignored)");
  if (decl.plugin.empty()) return std::nullopt;
  return decl;
}

ArtifactType SceneLoader::parseArtifact(const Descriptor& root) {
  ArtifactType t;
  if (root.name() != "artifact") {
    error(root.where(), "the root element of an artifact file must be <artifact>, got <" + root.name() + ">");
    t.ok = false;
    return t;
  }
  const std::size_t errors_before = diagnostics_.size();
  for (const Descriptor& c : root.children()) {
    if (c.name() == "physic") {
      PhysicNodeSpec spec = readPhysicNode(c);
      try {
        validatePhysicTree(spec);
        for (const auto& other : t.physic)
          if (!spec.name.empty() && other.name == spec.name)
            throw ConfigError(spec.where, "physic node '" + spec.name + "': duplicate node name in this artifact");
      } catch (const ConfigError& e) {
        record(e);
      }
      t.physic.push_back(std::move(spec));
    } else if (c.name() == "render") {
      t.render.push_back(readRenderNode(c, true));
    } else if (c.name() == "driver") {
      if (t.driver) {
        error(c.where(), "<driver>: an artifact has at most one driver");
        continue;
      }
      t.driver = readPluginDecl(c);
    } else if (c.name() == "sensor") {
      if (auto decl = readPluginDecl(c)) t.sensors.push_back(std::move(*decl));
    }
  }
  // render roots follow physic nodes by name
  for (std::size_t i = 0; i < t.render.size(); ++i) {
    const std::string& follow = t.render[i].follow;
    if (follow.empty()) continue;
    bool found = false;
    auto search = [&](auto& self, const PhysicNodeSpec& n) -> void {
      found = found || n.name == follow;
      for (const auto& c : n.children) self(self, c);
    };
    for (const auto& p : t.physic) search(search, p);
    if (!found) {
      const Descriptor& rd = *root.childrenNamed("render")[i];
      error(rd.where(), "<render>: follows unknown physic node '" + follow + "'");
    }
  }
  checkUnknown(root, {"physic", "render", "driver", "sensor"});
  for (std::size_t i = errors_before; i < diagnostics_.size(); ++i)
    if (diagnostics_[i].severity == Diagnostic::Severity::Error) t.ok = false;
  return t;
}

const ArtifactType* SceneLoader::artifactType(const std::string& name, const SourceLocation& where) {
  if (auto it = types_.find(name); it != types_.end()) return it->second.ok ? &it->second : nullptr;
  const auto decl = type_decls_.find(name);
  if (decl == type_decls_.end()) {
    std::string known;
    for (const auto& [k, v] : type_decls_) known += (known.empty() ? "" : ", ") + k;
    error(where,
          "unknown artifact type '" + name + "' (declared with <type>: " + (known.empty() ? "none" : known) + ")");
    types_[name].ok = false;
    return nullptr;
  }
  ArtifactType& t = types_[name];
  try {
    documents_.push_back(detail::readXmlFile(decl->second.file));
    t = parseArtifact(documents_.back());
  } catch (const ConfigError& e) {
    if (e.where().line == 0)
      error(decl->second.where, "<type>: cannot read artifact file '" + decl->second.file.string() +
                                    "' (missing, a directory, or no permission)");
    else
      record(e);
    t.ok = false;
  }
  return t.ok ? &t : nullptr;
}

// --- pass 2 --------------------------------------------------------------------------------------

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
                              std::int64_t period_steps, const std::string& what, const SourceLocation& period_from) {
  const ssx_plugin_class* type = env.classLoader().classOf(instance);
  if (type == nullptr) return;
  const PluginContext context{&env, artifact, period_steps, env.timestep(), period_from};
  for (auto& d : checkParameters({type->params, type->param_count}, params, context, what))
    diagnostics_.push_back(std::move(d));
  // unknown parameters were reported just now: not again when the environment starts
  for (const auto& a : params.attributes()) a.used = true;
}

void SceneLoader::validatePlugin(Environment& env, const void* instance, const Descriptor& params,
                                 const Artifact* artifact, std::int64_t period_steps, const std::string& what) {
  const ssx_plugin_class* type = env.classLoader().classOf(instance);
  if (type == nullptr || type->validate == nullptr) return;
  const PluginContext context{&env, artifact, period_steps, env.timestep(), {}};
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
      checkPlugin(env, d, params, &a, period, "driver '" + decl.class_name + "'", periodFrom(decl, driver_override));
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
                  periodFrom(decl, sensor_overrides[i]));
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
  positions.reserve(static_cast<std::size_t>(count));
  if (layout == "grid") {
    // rows along x, then y, then layers along z
    const double spacing = readPositive(d, "spacing", 1.0);
    const auto columns =
        readCount(d, "columns", static_cast<std::int64_t>(std::ceil(std::sqrt(static_cast<double>(count)))), 1);
    const auto rows = readCount(d, "rows", (count + columns - 1) / columns, 1);
    for (std::int64_t i = 0; i < count; ++i)
      positions.emplace_back(spacing * static_cast<double>(i % columns),
                             spacing * static_cast<double>((i / columns) % rows),
                             spacing * static_cast<double>(i / (columns * rows)));
  } else if (layout == "random") {
    const Vec3 lo = read<Vec3>(d, "min", Vec3(-1, -1, 0));
    const Vec3 hi = read<Vec3>(d, "max", Vec3(1, 1, 1));
    if (!(lo.array() <= hi.array()).all()) error(d.where(), "<swarm>: every component of 'min' must be <= 'max'");
    // a stream of its own, from the scene seed and the swarm's position among the swarms
    const double min_distance = read<double>(d, "min_distance", 0.0);
    Random rng(deriveSeed(settings_.seed, 0xa11ce5ULL, swarm_index));
    // rejection sampling keeps members at least min_distance apart (a grid of that cell size finds
    // the candidates' neighbours); give up after many misses
    const std::int64_t max_tries = 1000 * count;
    std::int64_t tries = 0;
    const double cell = min_distance > 0 ? min_distance : 1.0;
    std::unordered_map<std::int64_t, std::vector<std::size_t>> grid;
    auto cellKey = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
      return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
    };
    while (static_cast<std::int64_t>(positions.size()) < count && tries++ < max_tries) {
      const double x = rng.uniform(lo.x(), hi.x()), y = rng.uniform(lo.y(), hi.y()), z = rng.uniform(lo.z(), hi.z());
      const Vec3 p(x, y, z);
      const auto cx = static_cast<std::int64_t>(std::floor(x / cell)),
                 cy = static_cast<std::int64_t>(std::floor(y / cell)),
                 cz = static_cast<std::int64_t>(std::floor(z / cell));
      bool ok = true;
      for (std::int64_t dx = -1; dx <= 1 && ok && min_distance > 0; ++dx)
        for (std::int64_t dy = -1; dy <= 1 && ok; ++dy)
          for (std::int64_t dz = -1; dz <= 1 && ok; ++dz)
            if (const auto it = grid.find(cellKey(cx + dx, cy + dy, cz + dz)); it != grid.end())
              for (std::size_t q : it->second) ok = ok && (p - positions[q]).norm() >= min_distance;
      if (!ok) continue;
      grid[cellKey(cx, cy, cz)].push_back(positions.size());
      positions.push_back(p);
    }
    if (static_cast<std::int64_t>(positions.size()) < count) {
      error(d.where(), "<swarm>: could not place " + std::to_string(count) + " members " +
                           std::to_string(min_distance) + " m apart in the box: enlarge it or lower min_distance");
      positions.resize(static_cast<std::size_t>(count), Vec3::Zero());
    }
  } else {
    // Fibonacci sphere: z_i = 1 - 2 (i + 0.5) / N, theta_i = i pi (3 - sqrt 5)
    const double radius = readPositive(d, "radius", 1.0);
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (std::int64_t i = 0; i < count; ++i) {
      const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(count);
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      const double theta = golden * static_cast<double>(i);
      positions.emplace_back(radius * r * std::cos(theta), radius * r * std::sin(theta), radius * z);
    }
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

void SceneLoader::build(Scene& scene) {
  if (options_.seed) settings_.seed = *options_.seed;
  if (options_.threads) settings_.threads = *options_.threads;
  if (options_.render_engine) settings_.render.engine = *options_.render_engine;
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
  try {
    scene.environment = std::make_unique<Environment>(settings_);
  } catch (const ConfigError& e) {
    error(environment_element_ != nullptr ? environment_element_->where() : SourceLocation{scene.file.string(), 0},
          e.detail());
    // go on with defaults, so that the artifacts are checked too
    scene.environment = std::make_unique<Environment>(EnvironmentSettings{});
  }
  Environment& env = *scene.environment;
  // search order: the scene's directories, the caller's, then the installation's
  for (const auto& dir : plugin_dirs_) env.classLoader().addSearchDirectory(dir);
  for (const auto& dir : options_.plugin_path) env.classLoader().addSearchDirectory(dir);
  if (options_.search_installed_plugins) env.classLoader().addSearchDirectory(ClassLoader::installedPluginDirectory());

  for (const Entity& e : extensions_) {
    const Descriptor& d = *e.element;
    const std::string name = require(d, "name");
    std::optional<PluginDecl> decl = readPluginDecl(d);
    if (name.empty() || !decl) continue;
    decl->params.erase("name");  // the extension's name, read here
    try {
      SimulationExtension& ext = env.classLoader().createExtension(decl->plugin, decl->class_name);
      checkPlugin(env, &ext, decl->params, nullptr, 1, "extension '" + decl->class_name + "'");
      env.addExtension(name, ext, decl->params);
      extension_checks_.push_back({&ext, decl->params, "extension '" + decl->class_name + "'"});
    } catch (const PluginError& err) {
      error(d.where(), "<extension>: " + std::string(err.what()));
    } catch (const ConfigError& err) {
      error(d.where(), "<extension>: " + err.detail());
    }
  }

  std::size_t swarm_index = 0;
  for (const Entity& e : entities_) {
    const Descriptor& d = *e.element;
    if (d.name() == "artifact") {
      const std::string name = require(d, "name");
      const std::string type = require(d, "type");
      const Pose pose = readPose(d);
      checkUnknown(d, {"driver", "sensor"});
      if (!name.empty() && !type.empty()) place(env, name, type, pose, d);
    } else if (d.name() == "swarm") {
      buildSwarm(env, d, swarm_index++);
    } else if (d.name() == "ground") {
      const double z = read<double>(d, "z", 0.0);
      checkUnknown(d);
      if (env.findArtifact("ground") != nullptr)
        error(d.where(), "<ground>: an artifact named 'ground' exists already");
      else
        env.addGround(z);
    } else if (d.name() == "obstacle") {
      buildObstacle(env, d);
    }
  }
  // extensions check what they refer to (artifacts by name) once every artifact exists
  if (!hasErrors())
    for (const auto& c : extension_checks_) validatePlugin(env, c.extension, c.params, nullptr, 1, c.what);
  for (const auto& [name, where] : camera_follows_) {
    const Artifact* a = env.findArtifact(name);
    if (a == nullptr || a->rootCount() == 0)
      error(where, "<camera>: follows '" + name + "', which is no artifact with a physic root in this scene");
  }
}

Scene SceneLoader::load(Descriptor root, const fs::path& file, const fs::path& dir) {
  Scene scene;
  scene.file = file;
  documents_.push_back(std::move(root));
  std::error_code ec;
  std::vector<fs::path> stack{fs::weakly_canonical(file, ec)};
  collect(documents_.front(), dir, stack);
  // build even after errors, to report the problems of artifacts and plugins in the same go
  build(scene);
  if (hasErrors()) throw SceneError(std::move(diagnostics_));
  scene.run.realtime_factor = run_.realtime_factor;
  scene.run.overrun = run_.overrun;
  scene.duration = duration_;
  scene.warnings = std::move(diagnostics_);
  return scene;
}

}  // namespace

Scene loadScene(const fs::path& file, const SceneOptions& options) {
  Descriptor root;
  try {
    root = detail::readXmlFile(file);
  } catch (const ConfigError& e) {
    throw SceneError({{Diagnostic::Severity::Error, e.where(), e.detail()}});
  }
  SceneLoader loader(options);
  fs::path dir = file.parent_path();
  if (dir.empty()) dir = ".";
  return loader.load(std::move(root), file, dir);
}

Scene loadSceneFromString(std::string_view xml, const std::string& label, const fs::path& base_dir,
                          const SceneOptions& options) {
  Descriptor root;
  try {
    root = detail::parseXml(xml, label);
  } catch (const ConfigError& e) {
    throw SceneError({{Diagnostic::Severity::Error, e.where(), e.detail()}});
  }
  SceneLoader loader(options);
  return loader.load(std::move(root), label, base_dir);
}

}  // namespace ssx
