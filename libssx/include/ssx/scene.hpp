#pragma once
/// @file
/// Scenes and artifacts from XML files. The formats are described in docs/scene-format.md.

#include <ssx/environment.hpp>
#include <ssx/error.hpp>
#include <ssx/export.hpp>
#include <ssx/parameters.hpp>
#include <ssx/run_files.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ssx {

/// A scene could not be loaded. `what()` lists every error (and the warnings) found, one per
/// line; nothing was started.
class SSX_EXPORT SceneError : public Error {
 public:
  /// An error made of these diagnostics: what() lists them in the order given, then the count of errors.
  explicit SceneError(std::vector<Diagnostic> diagnostics);
  /// Every error and warning found, each with its file and line.
  const std::vector<Diagnostic>& diagnostics() const noexcept { return diagnostics_; }

 private:
  std::vector<Diagnostic> diagnostics_;
};

/// An attribute of the scene file set before the file is read: how a sweep varies a scene.
/// `target` is a path from `<scene>`: steps separated by '/', each `name`, `name[k]` (the k-th child
/// of that name, from 1) or `name[attribute=value]`, then `@attribute`; for example
/// `environment@timestep` or `swarm[name=quad{i}]/driver@formation_gain`. Every step must match
/// exactly one element of the scene file itself (not of its includes or artifact files), except
/// that a missing `driver` or `sensor[index=K]` of an `<artifact>` or `<swarm>` is added (that is
/// where a placement sets its type's plugin parameters), and so is a missing `<environment>`,
/// `<physics>` or `<render>`. A path that does not fit, and the
/// value's own problems, are reported at `where`.
struct AttributeOverride {
  std::string target;    ///< the path described above
  std::string value;     ///< the attribute's new text
  SourceLocation where;  ///< where the override was given (a sweep file's line), for messages
};

/// How to load a scene, beyond what the file says.
struct SceneOptions {
  /// Plugin directories searched after the scene's own `<plugin_path>`s and before the installed
  /// plugin directory (the CLI puts --plugin-path, then SSX_PLUGIN_PATH, here).
  std::vector<std::filesystem::path> plugin_path;
  std::optional<std::uint64_t> seed;         ///< overrides `<environment seed>`
  std::optional<int> threads;                ///< overrides `<environment threads>`
  std::optional<std::string> render_engine;  ///< overrides `<render engine>`
  /// Overrides `<physics engine>`; the scene's attributes of another engine are then errors.
  std::optional<std::string> physics_engine;
  /// Outputs for the first camera (a camera framing the whole scene is added if there is none):
  /// a PNG of the last frame, an MP4, a directory of PNG frames. Empty: as the scene says.
  std::filesystem::path snapshot;
  std::filesystem::path video;       ///< MP4 of the first camera (see snapshot)
  std::filesystem::path frames_dir;  ///< PNG frames of the first camera (see snapshot)
  bool search_installed_plugins = true;      ///< append ClassLoader::installedPluginDirectory()
  /// Directories where a `<type name="X"/>` without `file` finds `X.xml`, searched before the
  /// installed artifact directory (installedDataDirectory()/artifacts). A `file` always wins.
  std::vector<std::filesystem::path> artifact_path;
  bool search_installed_artifacts = true;    ///< append installedDataDirectory()/artifacts
  /// Where a URDF's `package://NAME/...` and an SDF's `model://NAME/...` are looked for (a folder
  /// NAME in one of them, or the directory NAME itself), before SSX_RESOURCE_PATH and then
  /// ROS_PACKAGE_PATH or GZ_SIM_RESOURCE_PATH (docs/robots.md).
  std::vector<std::filesystem::path> resource_path;
  /// Attributes set before the scene file is read (see AttributeOverride), in order.
  std::vector<AttributeOverride> overrides;
  /// false: the scene's `<extension>` elements are left out (headless batch runs: no logger writes,
  /// no bridge connects).
  bool extensions = true;
  /// Outputs written as streams (a logger's file) may be FIFOs or character devices (RunFiles).
  bool allow_special_outputs = false;
  /// The largest scene, include or artifact file read (readInputFile); `--max-input-mb`.
  std::uintmax_t max_input_bytes = kDefaultMaxInputBytes;
  /// The memory the scene's artifacts may need, estimated from the swarms' counts while parsing
  /// (0: this machine's physical memory). A swarm beyond it is an error at its line, not an abort
  /// when memory runs out.
  std::uintmax_t max_memory_bytes = 0;
  /// Where the scene's own outputs go when their paths are relative (a logger's file, a scene
  /// camera's snapshot, video or frames): empty, the working directory; `ssx run` gives
  /// `ssx-out/<scene>/` unless told `--out DIR`. The directory itself is the program's to make, after
  /// loading succeeded (the outputs are checked as in a directory about to be made).
  std::filesystem::path output_directory;
};

struct SceneModel;

/// A loaded scene: an environment ready to start, and how the file asks to run it.
struct Scene {
  std::filesystem::path file;                ///< the scene file (or the label of a scene in memory)
  std::unique_ptr<Environment> environment;  ///< populated, not started
  RunOptions run;                       ///< real-time factor and overrun policy from the file
  std::optional<Nanoseconds> duration;  ///< `<environment duration>`, if given
  std::vector<Diagnostic> warnings;     ///< unknown elements and attributes, and the like
  /// The files the scene was read from, and the outputs its plugins and cameras write, checked
  /// against each other; claim the program's own outputs here before anything runs.
  RunFiles files;
  /// The model the environment was built from (what a recording keeps: model->toXml()).
  std::shared_ptr<const SceneModel> model;
};

/// Where the installed artifact types (`artifacts/`) and example scenes (`scenes/`) are: the
/// package's data directory (`<prefix>/share/ssx`), found from the location of this libssx, so it
/// moves with the installation; in a build tree, `<build>/share/ssx`. Empty if there is none.
SSX_EXPORT std::filesystem::path installedDataDirectory();

/// Parses a scene file and every file it includes, loads every plugin it names and creates every
/// artifact. All problems are collected; if any is an error, throws SceneError before anything
/// is started.
SSX_EXPORT Scene loadScene(const std::filesystem::path& file, const SceneOptions& options = {});

/// Same, from text in memory; relative paths resolve against `base_dir`, messages say `label`.
SSX_EXPORT Scene loadSceneFromString(std::string_view xml, const std::string& label,
                                     const std::filesystem::path& base_dir, const SceneOptions& options = {});

/// A robot description from another simulator, as `ssx import` gives it.
struct ImportedRobot {
  std::string artifact_xml;        ///< the same robot as ssx's artifact file
  std::vector<Diagnostic> warnings;  ///< what was not imported (Gazebo extensions, textures, mimic joints...)
  std::size_t bodies = 0;          ///< rigid bodies (fixed joints merge links into one)
  std::size_t joints = 0;          ///< joints between them
  double mass = 0;                 ///< kg, of every link
};

/// Reads a URDF file (docs/robots.md) into ssx's artifact form, checks it as a scene would use it
/// (read and built on the default engine), and prints it as an artifact file; mesh paths are
/// written relative to `out_dir` (where the file will be) when they are below it. Throws
/// SceneError with every problem, each with its file and line.
SSX_EXPORT ImportedRobot importRobotDescription(const std::filesystem::path& file, const std::filesystem::path& out_dir = {},
                                                const SceneOptions& options = {});

}  // namespace ssx
