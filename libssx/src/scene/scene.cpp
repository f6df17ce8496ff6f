// Loading scenes (ssx/scene.hpp): the entry points of the scene loader (xml/scene_loader.hpp), its
// error, and where the installed data is.
#include "scene/builder.hpp"
#include "scene/import/robot_import.hpp"
#include "scene/xml/scene_loader.hpp"

#include <ssx/scene.hpp>
#include <ssx/scene_model.hpp>

#include <dlfcn.h>

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

fs::path installedDataDirectory() {
  // the directory of the libssx that holds this very function, then the data directory relative
  // to it as installed (SSX_DATA_FROM_LIBDIR, e.g. ../share/ssx) or as in a build tree
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&installedDataDirectory), &info) == 0 || info.dli_fname == nullptr) return {};
  std::error_code ec;
  const fs::path lib = fs::weakly_canonical(fs::path(info.dli_fname), ec).parent_path();
  for (const char* relative : {SSX_DATA_FROM_LIBDIR, "../share/ssx"}) {
    const fs::path dir = (lib / relative).lexically_normal();
    if (fs::is_directory(dir, ec)) return dir;
  }
  return {};
}

namespace {

Descriptor rootOf(const fs::path& file, std::uintmax_t max_bytes) {
  try {
    return readXmlFile(file, max_bytes);
  } catch (const ConfigError& e) {
    throw SceneError({{Diagnostic::Severity::Error, e.where(), e.detail()}});
  }
}

Descriptor rootOf(std::string_view xml, const std::string& label) {
  try {
    return parseXml(xml, label);
  } catch (const ConfigError& e) {
    throw SceneError({{Diagnostic::Severity::Error, e.where(), e.detail()}});
  }
}

fs::path directoryOf(const fs::path& file) {
  fs::path dir = file.parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

SceneModel parseWith(detail::SceneLoader& loader, Descriptor root, const fs::path& file, const fs::path& dir) {
  SceneModel model = loader.parse(std::move(root), file, dir);
  const bool failed = loader.hasErrors();
  std::vector<Diagnostic> found = loader.log().take();
  if (failed) throw SceneError(std::move(found));
  model.warnings = std::move(found);
  return model;
}

// read and built in one go: the problems of both together in document order, even when reading
// found errors
Scene load(const SceneOptions& options, Descriptor root, const fs::path& file, const fs::path& dir) {
  detail::SceneLoader loader(options);
  SceneModel model = loader.parse(std::move(root), file, dir);
  detail::SceneBuilder builder(options, loader.buildOrder());
  Scene scene = builder.build(model, false);
  detail::DiagnosticLog& log = loader.log();
  log.append(std::move(builder.log()));
  const bool failed = log.errorCount() > 0;
  std::vector<Diagnostic> found = log.take();
  if (failed) throw SceneError(std::move(found));
  scene.warnings = std::move(found);
  scene.model = std::make_shared<const SceneModel>(std::move(model));
  return scene;
}

}  // namespace

SceneModel parseScene(const fs::path& file, const SceneOptions& options) {
  detail::SceneLoader loader(options);
  return parseWith(loader, rootOf(file, options.max_input_bytes), file, directoryOf(file));
}

SceneModel parseSceneString(std::string_view xml, const std::string& label, const fs::path& base_dir,
                            const SceneOptions& options) {
  detail::SceneLoader loader(options);
  return parseWith(loader, rootOf(xml, label), label, base_dir);
}

Scene buildScene(const SceneModel& model, const SceneOptions& options) {
  detail::SceneBuilder builder(options);
  Scene scene = builder.build(model, true);
  const bool failed = builder.log().errorCount() > 0;
  std::vector<Diagnostic> found = model.warnings;
  for (auto& d : builder.log().take()) found.push_back(std::move(d));
  if (failed) throw SceneError(std::move(found));
  scene.warnings = std::move(found);
  scene.model = std::make_shared<const SceneModel>(model);
  return scene;
}

ImportedRobot importRobotDescription(const fs::path& file, const fs::path& out_dir, const SceneOptions& options) {
  ImportedRobot out;
  detail::DiagnosticLog log;
  const detail::ResourcePath resources{options.resource_path};
  const Descriptor artifact = detail::importRobot(file, resources, options.max_input_bytes, log);
  if (log.errorCount() > 0) throw SceneError(log.take());
  // the artifact checked as a scene would use it: read as an artifact file and built on the engine
  std::error_code ec;
  const fs::path absolute = fs::absolute(file, ec);
  const std::string name = "robot";
  const std::string scene = "<scene><type name=\"" + name + "\" file=\"" + absolute.string() +
                            "\"/><artifact name=\"" + name + "\" type=\"" + name + "\" allow_overlap=\"true\"/></scene>";
  SceneOptions checking = options;
  checking.extensions = false;
  Scene loaded = loadSceneFromString(scene, file.string(), directoryOf(file), checking);
  out.warnings = log.take();
  out.artifact_xml = detail::artifactXml(artifact, out_dir,
                                         "made by `ssx import` from " + file.filename().string() +
                                             " (docs/robots.md): edit it, and give it as a <type file>");
  const Artifact& a = *loaded.environment->findArtifact(name);
  out.bodies = 0;
  for (std::size_t i = 0; i < a.nodeCount(); ++i)
    if (a.nodeAt(i).parent() == nullptr || a.nodeAt(i).spec().joint.isBody()) ++out.bodies;
  for (std::size_t i = 0; i < a.nodeCount(); ++i)
    if (a.nodeAt(i).spec().joint.isBody()) ++out.joints;
  for (std::size_t i = 0; i < a.rootCount(); ++i) out.mass += combinedMass(a.root(i).spec()).mass;
  return out;
}

Scene loadScene(const fs::path& file, const SceneOptions& options) {
  return load(options, rootOf(file, options.max_input_bytes), file, directoryOf(file));
}

Scene loadSceneFromString(std::string_view xml, const std::string& label, const fs::path& base_dir,
                          const SceneOptions& options) {
  return load(options, rootOf(xml, label), label, base_dir);
}

}  // namespace ssx
