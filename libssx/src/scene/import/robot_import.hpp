#pragma once
// Robot descriptions written for other simulators (URDF, SDFormat) read into ssx's own artifact
// form: an <artifact> element as an artifact file would hold it, every element stamped with the
// line of the description it came from, so that the artifact reader checks and reports it as it
// does ssx's own files and `ssx import` prints it back as an artifact file.

#include <ssx/descriptor.hpp>

#include "scene/diagnostic_log.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace ssx::detail {

namespace fs = std::filesystem;

// where `package://` and `model://` resources are looked for: the scene's own directories first,
// then SSX_RESOURCE_PATH, then ROS_PACKAGE_PATH (package://) or GZ_SIM_RESOURCE_PATH (model://)
struct ResourcePath {
  std::vector<fs::path> dirs;  // given by the program (SceneOptions::resource_path)

  // a resource's file: `uri` relative to `base` (the description's directory), or a
  // package:// or model:// URI, or file:// and absolute paths; empty with `problem` said when
  // no file is found
  fs::path resolve(const std::string& uri, const fs::path& base, std::string& problem) const;
};

// A joint as the importers read it (URDF, SDF), before it is written as a node's attributes.
struct ImportedJoint {
  enum class Kind { Hinge, Slider, Ball };
  Kind kind = Kind::Hinge;
  std::string name;
  bool continuous = false;  // a hinge without limits
  Vec3 axis = Vec3::UnitZ();
  double lower = 0, upper = 0;  // equal: no limits
  double effort = 0, velocity = 0, damping = 0, friction = 0;  // 0: none
};

// the shortest text that reads back as the same double
std::string formatValue(double v);
// a node's xyz and rpy (left out where zero)
void setPoseAttributes(Descriptor& node, const Pose& pose);
// a node's mass, centre of mass and inertia about it (node axes)
void setInertial(Descriptor& node, double mass, const Mat3& inertia, const Vec3& com);
// a node's joint attributes; what ssx's joints cannot hold is said at `where`
void setJoint(Descriptor& node, const ImportedJoint& joint, const SourceLocation& where, DiagnosticLog& log);

// whether `file` is read by an importer (by its extension: .urdf, .sdf, .world)
bool isRobotDescription(const fs::path& file);

// The description in `file` as an <artifact>; its problems (file:line) go to `log`. An element
// the description has and ssx does not (a Gazebo <plugin>, a <transmission>) is reported as a
// warning that names it.
Descriptor importUrdf(const fs::path& file, const ResourcePath& resources, std::uintmax_t max_bytes, DiagnosticLog& log);
Descriptor importSdf(const fs::path& file, const ResourcePath& resources, std::uintmax_t max_bytes, DiagnosticLog& log);
// importUrdf or importSdf, by the file's extension
Descriptor importRobot(const fs::path& file, const ResourcePath& resources, std::uintmax_t max_bytes, DiagnosticLog& log);

// An artifact descriptor as an artifact file; mesh files are written relative to `dir` (where
// the file will be) when they are below it, absolute otherwise.
std::string artifactXml(const Descriptor& artifact, const fs::path& dir, const std::string& comment);

}  // namespace ssx::detail
