#pragma once
// The scene reader: scene and artifact files into a SceneModel. Pass 1 collects every element of
// the scene and its includes and reads the settings (scene_loader.cpp); artifact files are read
// when a type is first used (artifact_reader.cpp); then every placement (placement.cpp). Every
// problem is collected, stamped with its element's stage, so that scene/builder.hpp's (which
// builds the model) come after each element's own: any error stops the load before anything starts.

#include <cstdio>
#include <ssx/scene.hpp>
#include <ssx/scene_model.hpp>

#include "scene/diagnostic_log.hpp"
#include "scene/import/mesh_loader.hpp"

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

using PluginDecl = PluginDeclaration;

// an artifact type as the loader keeps it: the model, and whether its file was read without errors
struct ArtifactType : ArtifactTypeModel {
  bool ok = true;
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
/// (`identity`: set to the attribute's identity in the document, the same for every spelling of
/// its target)
std::optional<std::string> applyOverride(Descriptor& scene, const AttributeOverride& o, std::string* identity = nullptr);

class SceneLoader {
 public:
  explicit SceneLoader(const SceneOptions& options) : options_(options) {}

  // the files into a model (what could not be read is left out of it and reported)
  SceneModel parse(Descriptor root, const fs::path& file, const fs::path& dir);
  // where each extension and placement of the model parsed was read: what a builder stamps its
  // problems after
  BuildOrder buildOrder() const { return {extension_stage_, placement_stage_, hasErrors()}; }
  bool hasErrors() const { return errorCount() > 0; }
  DiagnosticLog& log() { return log_; }

 private:
  // --- diagnostics, each stamped with where in the document it belongs (see DiagnosticLog) ---
  void add(Diagnostic d) { log_.add(std::move(d)); }
  void error(const SourceLocation& where, std::string message) { log_.error(where, std::move(message)); }
  void warning(const SourceLocation& where, std::string message) { log_.warning(where, std::move(message)); }
  static std::int64_t stage(std::int64_t major, std::int64_t minor = 0) { return documentStage(major, minor); }
  void record(const ConfigError& e) { error(e.where(), e.detail()); }
  std::size_t errorCount() const { return log_.errorCount(); }

  // --- typed reads that record errors and fall back ---
  // every attribute a read asked for, per element: what an unknown attribute may have meant
  void asked(const Descriptor& d, std::string_view key) {
    auto& keys = asked_[&d];
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.emplace_back(key);
  }
  template <class T>
  T read(const Descriptor& d, std::string_view key, const T& fallback) {
    asked(d, key);
    try {
      return d.get<T>(key, fallback);
    } catch (const ConfigError& e) {
      record(e);
      return fallback;
    }
  }
  template <class T>
  std::optional<T> readOptional(const Descriptor& d, std::string_view key) {
    asked(d, key);
    if (!d.has(key)) return std::nullopt;
    try {
      return d.get<T>(key);
    } catch (const ConfigError& e) {
      record(e);
      return std::nullopt;
    }
  }
  std::string require(const Descriptor& d, std::string_view key) {
    asked(d, key);
    if (!d.has(key)) {
      error(d.where(), "<" + d.name() + ">: missing attribute '" + std::string(key) + "'");
      return {};
    }
    return d.get<std::string>(key);
  }
  double readPositive(const Descriptor& d, std::string_view key, double fallback) {
    asked(d, key);
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
    return poseFromXyzRpy(read<Vec3>(d, "xyz", Vec3::Zero()), read<Vec3>(d, "rpy", Vec3::Zero()));
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
  // (with the nearest name it asked for or allows, when one is near: a typing slip)
  void checkUnknown(const Descriptor& d, const std::set<std::string>& children = {}) {
    const auto it = asked_.find(&d);
    const std::vector<std::string> none;
    const auto ignored = [](std::string_view name, const std::vector<std::string>& known) {
      const std::string nearest = nearestName(name, known);
      return nearest.empty() ? std::string(" (ignored)") : " (ignored; did you mean '" + nearest + "'?)";
    };
    for (const auto& a : d.attributes())
      if (!a.used)
        warning(a.where, "unknown attribute '" + a.key + "' of <" + d.name() + ">" +
                             ignored(a.key, it != asked_.end() ? it->second : none));
    const std::vector<std::string> allowed(children.begin(), children.end());
    for (const auto& c : d.children())
      if (!children.contains(c.name()))
        warning(c.where(), "unknown element <" + c.name() + "> in <" + d.name() + ">" + ignored(c.name(), allowed));
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
  // records where each attribute of a settings element was written, under path@attribute
  void noteSettings(const Descriptor& d, const std::string& path);
  void readEnvironment(const Descriptor& d);
  void readPhysics(const Descriptor& d);
  void readRender(const Descriptor& d);
  void readWind(const Descriptor& d);
  bool once(const Descriptor& d, const Descriptor*& slot);

  // --- artifact files ---
  const ArtifactType* artifactType(const std::string& name, const SourceLocation& where);
  ArtifactType parseArtifact(const Descriptor& root);
  // (xyz, rpy: set to the shape's position and angles as written)
  Shape readShape(const Descriptor& d, Vec3* xyz = nullptr, Vec3* rpy = nullptr);
  // a <mesh file scale>'s mesh (file relative to the artifact file), or nullptr when it cannot be read
  // (`collides`: for a physic node, which needs its convex hull)
  std::shared_ptr<const TriangleMesh> readMesh(const Descriptor& d, bool collides);
  void readJoint(const Descriptor& d, JointSpec& joint);
  // a <type>'s <joint node="..." .../>: its settings written onto the file's physic node `node`
  void setJoint(const Descriptor& setting, Descriptor& document);
  PhysicNodeSpec readPhysicNode(const Descriptor& d);
  RenderNodeSpec readRenderNode(const Descriptor& d, bool is_root);
  std::optional<PluginDecl> readPluginDecl(const Descriptor& d);

  // --- the rest of parsing: options, extensions, placements ---
  void applyOptions();
  void readExtensions();
  void readPlacements();
  bool readOverrides(const Descriptor& d, PlacementModel& p);
  bool readSwarm(const Descriptor& d, PlacementModel& p, std::size_t swarm_index);
  // refuses a swarm whose members, with the scene's artifacts before it, cannot fit in memory
  void checkMemory(const Descriptor& d, const PlacementModel& p);
  bool readObstacle(const Descriptor& d, PlacementModel& p);

  const SceneOptions& options_;
  DiagnosticLog log_;
  std::vector<std::int64_t> extension_stage_;  // per extension of the model: its entity's stage
  std::vector<std::int64_t> placement_stage_;  // per placement of the model: its entity's stage
  MeshCache meshes_;
  fs::path artifact_dir_;  // of the artifact file being read (its meshes' paths are relative to it)
  std::deque<Descriptor> documents_;  // every file read, kept alive for the pointers below
  SceneModel model_;  // what parse fills in
  EnvironmentSettings& settings_ = model_.settings;
  RunOptions& run_ = model_.run;
  std::optional<Nanoseconds>& duration_ = model_.duration;
  const Descriptor* environment_element_ = nullptr;
  const Descriptor* physics_element_ = nullptr;
  const Descriptor* wind_element_ = nullptr;
  const Descriptor* render_element_ = nullptr;
  bool render_engine_named_ = false;  // <render engine="..."> given (then outputs do not switch it)
  std::vector<fs::path>& plugin_dirs_ = model_.plugin_dirs;
  std::vector<Entity> extensions_;
  std::vector<Entity> entities_;
  struct TypeDecl {
    fs::path file;
    SourceLocation where;
    std::vector<const Descriptor*> plugins;  // <driver> and <sensor> children: added to the type's own
    std::vector<const Descriptor*> joints;   // <joint> children: set on the file's nodes (setJoint)
  };
  std::map<std::string, TypeDecl> type_decls_;
  std::map<std::string, ArtifactType> types_;          // by type name, parsed on first use
  double placed_bytes_ = 0;
  std::map<const Descriptor*, std::vector<std::string>> asked_;  // see asked()                            // estimated memory of the artifacts so far
};

}  // namespace ssx::detail
