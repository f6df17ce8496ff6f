// Loading scenes (ssx/scene.hpp): the entry points of the scene loader (xml/scene_loader.hpp), its
// error, and where the installed data is.
#include "xml/scene_loader.hpp"

#include <ssx/scene.hpp>

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

Scene loadScene(const fs::path& file, const SceneOptions& options) {
  Descriptor root;
  try {
    root = readXmlFile(file);
  } catch (const ConfigError& e) {
    throw SceneError({{Diagnostic::Severity::Error, e.where(), e.detail()}});
  }
  detail::SceneLoader loader(options);
  fs::path dir = file.parent_path();
  if (dir.empty()) dir = ".";
  return loader.load(std::move(root), file, dir);
}

Scene loadSceneFromString(std::string_view xml, const std::string& label, const fs::path& base_dir,
                          const SceneOptions& options) {
  Descriptor root;
  try {
    root = parseXml(xml, label);
  } catch (const ConfigError& e) {
    throw SceneError({{Diagnostic::Severity::Error, e.where(), e.detail()}});
  }
  detail::SceneLoader loader(options);
  return loader.load(std::move(root), label, base_dir);
}

}  // namespace ssx
