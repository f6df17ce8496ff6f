#pragma once
// The scene builder: a SceneModel into an Environment, from the model alone (no file is read but
// the presets the plugins name). Loads the plugins, places every artifact and obstacle, checks
// every plugin parameter against its class's declarations and by the class's own validate, claims
// the run's outputs and finds robots that start inside one another. Every problem is collected,
// stamped with its element's stage so that, merged with the reader's, they come in document order.

#include <ssx/plugin_abi.hpp>
#include <ssx/scene.hpp>
#include <ssx/scene_model.hpp>

#include <ssx/run_files.hpp>
#include "plugin/presets.hpp"
#include "scene/diagnostic_log.hpp"

#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace ssx::detail {

class SceneBuilder {
 public:
  explicit SceneBuilder(const SceneOptions& options, BuildOrder order = {})
      : options_(options), order_(std::move(order)) {}

  // the model into an environment (placements of types the model lacks are reported when
  // `report_missing_types`; a reader that made the model reported them already)
  Scene build(const SceneModel& model, bool report_missing_types);
  DiagnosticLog& log() { return log_; }

 private:
  void error(const SourceLocation& where, std::string message) { log_.error(where, std::move(message)); }
  std::size_t errorCount() const { return log_.errorCount(); }
  std::int64_t extensionStage(std::size_t j) const {
    return (j < order_.extensions.size() ? order_.extensions[j] : documentStage(1, 2 * static_cast<std::int64_t>(j))) + 1;
  }
  std::int64_t placementStage(std::size_t k) const {
    return (k < order_.placements.size() ? order_.placements[k] : documentStage(2, 2 * static_cast<std::int64_t>(k))) + 1;
  }

  void buildExtensions(Environment& env, const SceneModel& model);
  void buildObstacle(Environment& env, const PlacementModel& p);
  void buildSwarm(Environment& env, const PlacementModel& p, const ArtifactTypeModel& type);
  // returns false when it reported an error
  bool place(Environment& env, const std::string& name, const PlacementModel& p, const ArtifactTypeModel& type,
             const Pose& pose, const std::string& index = {});
  // the camera outputs claimed with the plugins'
  void checkCameras(const SceneModel& model);
  // cameras follow artifacts that exist
  void checkFollowedNodes(const Environment& env, const SceneModel& model);
  // reports every robot that starts inside another artifact (scene/start_overlaps.cpp);
  // placement_of[a]: the placement that made artifact a
  void checkStartOverlaps(const Environment& env, const SceneModel& model, const std::vector<std::size_t>& placement_of);

  // --- plugins (scene/plugin_checks.cpp) ---
  template <class T, class Create>
  T* createPlugin(const PluginDeclaration& decl, Create create);
  // checks a plugin's parameters against its class's declarations (defaults added). `decl` and
  // `overrides`: the parameters are that declaration's with that placing element's on top (its {i}
  // replaced), so after a check of the same class, declaration, element and period that found
  // nothing, only the values holding {i} are checked again (a swarm's members)
  void checkPlugin(Environment& env, const void* instance, Descriptor& params, const Artifact* artifact,
                   std::int64_t period_steps, const std::string& what, const SourceLocation& period_from = {},
                   const PluginDeclaration* decl = nullptr, const Descriptor* overrides = nullptr);
  // runs a class's own validate on a parameter set that passed checkPlugin
  void validatePlugin(Environment& env, const void* instance, const Descriptor& params, const Artifact* artifact,
                      std::int64_t period_steps, const std::string& what);
  // the type's plugin parameters, with those given on the placing element on top ({i}: `index`)
  static Descriptor withOverrides(const PluginDeclaration& decl, const Descriptor* overrides, const std::string& index);
  // the period in steps, and where it was set: the placing element's, else the type's
  std::int64_t periodOf(const PluginDeclaration& decl, const Descriptor* overrides);
  static SourceLocation periodFrom(const PluginDeclaration& decl, const Descriptor* overrides);

  const SceneOptions& options_;
  BuildOrder order_;
  DiagnosticLog log_;
  RunFiles files_;  // the inputs, and the outputs claimed so far
  std::optional<Presets> presets_;  // made at the first plugin checked
  std::set<std::string> reported_presets_;  // the presets' problems reported (each once)
  std::map<std::string, std::string> failed_plugins_;  // "plugin/class" -> already reported
  // (class, declaration, placing element, period) whose check found nothing -> the parameters
  // whose values differ between the members (they hold {i}), for checkPlugin
  std::map<std::tuple<const void*, const PluginDeclaration*, const Descriptor*, std::int64_t>, std::vector<std::string>>
      clean_checks_;
  // what each class's validate shares between its instances (PluginContext::shared)
  std::map<const void*, PluginContext::SharedValues> validate_shared_;
  struct ExtensionCheck {
    const SimulationExtension* extension;
    Descriptor params;
    std::string what;
  };
  std::vector<ExtensionCheck> extension_checks_;
};

}  // namespace ssx::detail
