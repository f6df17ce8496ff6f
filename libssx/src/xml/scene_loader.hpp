#pragma once
// The scene loader: scene and artifact files into an Environment, in two passes. Pass 1 collects
// every element of the scene and its includes (scene_loader.cpp) and reads artifact files when a
// type is first used (artifact_reader.cpp); pass 2 places artifacts, creates their plugins and
// checks every parameter against its class's declarations (placement.cpp). Every problem is
// collected; any error stops the load before anything starts.

#include <cstdio>
#include <ssx/scene.hpp>

#include <array>
#include <deque>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace ssx::detail {

namespace fs = std::filesystem;

struct PluginDecl {
  std::string plugin;
  std::string class_name;
  std::int64_t period = 1;
  SourceLocation period_from;  // where `period` was given, if it was
  Descriptor params;
};

struct ArtifactType {
  bool ok = true;
  std::vector<std::shared_ptr<const PhysicNodeSpec>> physic;  // shared by every instance
  std::vector<std::shared_ptr<const RenderNodeSpec>> render;  // shared by every instance
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
inline const std::set<std::string> kShapeElements{"box", "sphere", "cylinder", "capsule"};

// Sets the attribute an override names in the tree of a scene file (see AttributeOverride);
// returns what is wrong with its target, if anything.
std::optional<std::string> applyOverride(Descriptor& scene, const AttributeOverride& o);

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
  // positive and at most `max` (`why` says where the bound comes from)
  double readPositiveAtMost(const Descriptor& d, std::string_view key, double fallback, double max,
                            const std::string& why) {
    const double v = readPositive(d, key, fallback);
    if (v <= max) return v;
    char text[64];
    std::snprintf(text, sizeof text, "%g", max);
    record(d.error(*d.find(key), "attribute '" + std::string(key) + "' must be at most " + text + " (" + why +
                                     "), got '" + d.find(key)->value + "'"));
    return fallback;
  }
  // a whole number in [min, max]; the upper bounds keep absurd input from allocating the machine away
  std::int64_t readCount(const Descriptor& d, std::string_view key, std::int64_t fallback, std::int64_t min,
                         std::int64_t max = kMaxCount) {
    const std::int64_t v = read<std::int64_t>(d, key, fallback);
    if (v < min || v > max) {
      record(d.errorAt(key, "attribute '" + std::string(key) + "' must be " +
                                (v < min ? "at least " + std::to_string(min) : "at most " + std::to_string(max)) +
                                ", got " + std::to_string(v)));
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
  // an installed artifact type by name (options_.artifact_path, then the installed directory);
  // records the error and returns empty when there is none
  fs::path findArtifactType(const Descriptor& d, const std::string& name);
  void readEnvironment(const Descriptor& d);
  void readPhysics(const Descriptor& d);
  void readRender(const Descriptor& d);
  void readWind(const Descriptor& d);
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
  // checks a plugin's parameters against its class's declarations (defaults added). `decl` and
  // `overrides`: the parameters are that declaration's with that placing element's on top (its {i}
  // replaced), so after a check of the same class, declaration, element and period that found
  // nothing, only the values holding {i} are checked again (a swarm's members)
  void checkPlugin(Environment& env, const void* instance, Descriptor& params, const Artifact* artifact,
                   std::int64_t period_steps, const std::string& what, const SourceLocation& period_from = {},
                   const PluginDecl* decl = nullptr, const Descriptor* overrides = nullptr);
  // runs a class's own validate on a parameter set that passed checkPlugin
  void validatePlugin(Environment& env, const void* instance, const Descriptor& params, const Artifact* artifact,
                      std::int64_t period_steps, const std::string& what);

  const SceneOptions& options_;
  std::vector<Diagnostic> diagnostics_;
  // (class, declaration, placing element, period) whose check found nothing -> the parameters
  // whose values differ between the members (they hold {i}), for checkPlugin
  std::map<std::tuple<const void*, const PluginDecl*, const Descriptor*, std::int64_t>, std::vector<std::string>>
      clean_checks_;
  // what each class's validate shares between its instances (PluginContext::shared)
  std::map<const void*, PluginContext::SharedValues> validate_shared_;
  std::deque<Descriptor> documents_;  // every file read, kept alive for the pointers below
  EnvironmentSettings settings_;
  RunOptions run_;
  std::optional<Nanoseconds> duration_;
  const Descriptor* environment_element_ = nullptr;
  const Descriptor* physics_element_ = nullptr;
  const Descriptor* wind_element_ = nullptr;
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

}  // namespace ssx::detail
