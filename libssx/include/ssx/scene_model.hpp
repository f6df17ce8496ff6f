#pragma once
/// @file
/// A scene as a plain value, between the file and the world: what a scene file and its includes
/// and artifact files say, parsed and checked, with every default filled in, before any plugin is
/// loaded or any artifact made. Loading is two steps: parseScene() (the files into a SceneModel)
/// and buildScene() (a SceneModel into an Environment: plugins loaded, their parameters checked
/// against their declarations and by their own validate, artifacts made). loadScene() does both,
/// reporting the problems of both together. A model prints back to scene XML (toXml(), what
/// `ssx validate --print` shows), and two models compare equal when they print the same.

#include <ssx/descriptor.hpp>
#include <ssx/environment.hpp>
#include <ssx/export.hpp>
#include <ssx/parameters.hpp>
#include <ssx/physic_node.hpp>
#include <ssx/pose_stream.hpp>
#include <ssx/render.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ssx {

struct SceneOptions;
struct Scene;

/// A pose from a position and fixed-axis roll, pitch and yaw in rad (as URDF: R = Rz(yaw) Ry(pitch)
/// Rx(roll)), as scene and artifact files write poses (`xyz`, `rpy`).
SSX_EXPORT Pose poseFromXyzRpy(const Vec3& xyz, const Vec3& rpy);

/// A plugin as a file declares it: `<driver plugin="..." class="..." period="..." .../>`.
struct PluginDeclaration {
  std::string plugin;          ///< the library (libssx_`<plugin>`.so)
  std::string class_name;      ///< the class in it (default: the library's name)
  std::int64_t period = 1;     ///< steps between two runs
  SourceLocation period_from;  ///< where `period` was given, if it was
  Descriptor params;           ///< its parameters as written (checked against its class when built)
};

/// An artifact file, parsed: its node trees and the plugins it declares.
struct ArtifactTypeModel {
  std::string name;            ///< as `<type name>` declares it
  std::filesystem::path file;  ///< the artifact file
  SourceLocation where;        ///< of the `<type>`
  std::vector<std::shared_ptr<const PhysicNodeSpec>> physic;  ///< shared by every instance
  std::vector<std::shared_ptr<const RenderNodeSpec>> render;  ///< shared by every instance
  std::optional<PluginDeclaration> driver;  ///< its driver, if it declares one
  std::vector<PluginDeclaration> sensors;   ///< its sensors, by index
  /// What the scene's `<type>` itself adds (a URDF or SDF robot's plugins): its `<driver>`, if
  /// any, and its `<sensor>`s, also in `driver` and at the end of `sensors`
  std::optional<PluginDeclaration> type_driver;
  std::vector<PluginDeclaration> type_sensors;  ///< (see type_driver)
  /// The scene's `<joint node="..." .../>` children of `<type>`, as written: joint settings
  /// (max_torque, max_force, max_velocity, damping, friction, lower, upper) set on the file's
  /// physic node `node` before the file is read (a URDF's wheels that have no `<limit effort>`)
  std::vector<Descriptor> type_joints;
};

/// A shape of an `<obstacle>` as written: `<box size>`, `<sphere radius>`, `<cylinder radius length>`
/// or `<capsule radius length>`, with its `xyz`, `rpy` and `density`.
struct ShapeModel {
  Shape shape;  ///< the geometry; its pose is poseFromXyzRpy(xyz, rpy)
  Vec3 xyz = Vec3::Zero();  ///< as written: position in the obstacle's frame, m
  Vec3 rpy = Vec3::Zero();  ///< as written: fixed-axis roll, pitch, yaw, rad
  SourceLocation where;     ///< of its element
};

/// One element of the scene that makes artifacts, in document order: an `<artifact>`, a `<swarm>`
/// (its members' places worked out), the `<ground>` or an `<obstacle>`.
struct SSX_EXPORT PlacementModel {
  /// Which element it is.
  enum class Kind : std::uint8_t { Artifact, Swarm, Ground, Obstacle };
  Kind kind = Kind::Artifact;  ///< which element it is
  SourceLocation where;        ///< of the element
  std::string name;  ///< the artifact's or obstacle's name; a swarm's name pattern (with {i})
  std::string type;  ///< the artifact type (artifacts, swarms)
  Vec3 xyz = Vec3::Zero();  ///< as written: position, m
  Vec3 rpy = Vec3::Zero();  ///< as written: fixed-axis roll, pitch, yaw, rad
  Pose pose() const;                            ///< from xyz and rpy
  /// Parameters the placing element sets on its type's plugins: `<driver .../>` and
  /// `<sensor index="k" .../>` inside it (null: none). A swarm's members share them; {i} in a value is the
  /// member's index.
  std::shared_ptr<const Descriptor> driver;
  std::vector<std::shared_ptr<const Descriptor>> sensors;  ///< by sensor index of the type
  /// `<ghost>` inside it: the artifact (each member of a swarm) is a ghost with these settings
  /// (Environment::setGhost); its type's driver is left out.
  std::optional<PoseStream::Settings> ghost;
  SourceLocation ghost_where;  ///< of the `<ghost>`
  // a swarm
  std::int64_t count = 1;        ///< swarm: how many members
  std::int64_t first_index = 0;  ///< swarm: the first member's {i}
  /// `allow_overlap="true"` (artifacts, swarms, obstacles): it may start overlapping other
  /// artifacts (a robot in its dock). Otherwise a robot that starts inside another, an obstacle
  /// or the ground is an error, found when the scene is built.
  bool allow_overlap = false;
  /// `present="false"` (artifacts, swarms): it starts out of the world (Environment::despawn),
  /// held in reserve until something spawns it (Environment::spawn, ROS 2's /spawn_entity).
  bool present = true;
  std::string layout = "grid";  ///< grid, random or sphere
  double spacing = 1.0;         ///< grid
  std::int64_t columns = 0;     ///< grid: members per row (parsing fills in ceil(sqrt(count)) when not given)
  std::int64_t rows = 0;        ///< grid: rows (parsing fills in as many as needed)
  Vec3 min = Vec3(-1, -1, 0);   ///< random: the box's lower corner
  Vec3 max = Vec3(1, 1, 1);     ///< random: the box's upper corner
  double min_distance = 0;                            ///< random
  double radius = 1.0;                                ///< sphere
  std::vector<Vec3> positions;  ///< the members' places in the swarm's frame (xyz, rpy)
  bool random_yaw = false;      ///< each member turned about z by its own uniform angle
  std::vector<double> yaws;     ///< with random_yaw: each member's turn, rad, from a stream of the scene seed
  std::string memberName(std::int64_t k) const;  ///< member k's name (the pattern with {i} = first_index + k)
  /// An obstacle's shapes, in the obstacle's frame, in the order written (the ground has none: its
  /// height is xyz.z()).
  std::vector<ShapeModel> shapes;
  Color color{0.55f, 0.55f, 0.6f, 1.0f};  ///< an obstacle's colour, rgba in 0..1
};

/// An `<extension>`: its name and its plugin.
struct ExtensionModel {
  std::string name;          ///< unique among the scene's extensions
  PluginDeclaration plugin;  ///< its plugin, class and parameters
};

/// A scene as a value: everything a scene file says, parsed and checked, with no environment
/// built (parseScene makes one; buildScene turns it into an environment). What `ssx validate`
/// checks, what a sweep varies and what a recording keeps.
struct SSX_EXPORT SceneModel {
  std::filesystem::path file;  ///< the scene file, or the label of a scene in memory
  EnvironmentSettings settings;  ///< timestep, seed, threads, physics, render, wind (defaults filled in)
  RunOptions run;                          ///< realtime_factor and overrun, as the file says
  std::optional<Nanoseconds> duration;     ///< `<environment duration>`
  std::vector<std::filesystem::path> plugin_dirs;  ///< `<plugin_path>`s, resolved
  std::vector<ExtensionModel> extensions;  ///< in document order
  std::map<std::string, ArtifactTypeModel> types;  ///< the types the placements use, by name
  std::vector<PlacementModel> placements;          ///< in document order
  std::vector<Diagnostic> warnings;                ///< unknown elements and attributes, and the like
  /// Every file read: the scene file, its includes, the artifact files (the run's inputs).
  std::vector<std::filesystem::path> files;
  /// Where each setting the file gives was written (the settings above hold the values, defaults
  /// included), keyed `element@attribute` as sweep overrides spell them: `environment@timestep`,
  /// `physics@engine`, `wind@speed`, `render@rate_hz`, `render/camera[name=top]@xyz`. A setting
  /// the file leaves out has no entry (its value is the default).
  std::map<std::string, SourceLocation> settings_from;

  /// The scene as scene XML with every setting's default filled in: plugin directories, artifact
  /// files and paths absolute; swarms with every layout attribute; plugin parameters and
  /// obstacles as written. Parsing it gives an equal model.
  std::string toXml() const;
};

/// The same scene, as printed (toXml()); where each value came from does not count.
SSX_EXPORT bool operator==(const SceneModel& a, const SceneModel& b);

/// Reads a scene file, its includes and the artifact files its placements use into a model,
/// applying `options`' overrides (seed, threads, engines, attribute overrides, outputs). Loads no
/// plugin. Throws SceneError listing every problem found.
SSX_EXPORT SceneModel parseScene(const std::filesystem::path& file, const SceneOptions& options);
/// Same, from text in memory; relative paths resolve against `base_dir`, messages say `label`.
SSX_EXPORT SceneModel parseSceneString(std::string_view xml, const std::string& label,
                                       const std::filesystem::path& base_dir, const SceneOptions& options);
/// Builds the environment of a model: loads its plugins (search path: the model's plugin
/// directories, `options.plugin_path`, then the installed plugin directory), checks every
/// parameter against its class's declarations and by the class's own validate, makes every
/// artifact. Starts nothing. Throws SceneError listing every problem found.
SSX_EXPORT Scene buildScene(const SceneModel& model, const SceneOptions& options);

}  // namespace ssx
