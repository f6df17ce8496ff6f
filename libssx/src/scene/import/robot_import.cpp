// What every importer shares: finding a description's resources (meshes) and printing what it
// made as an artifact file (`ssx import`).
#include "scene/import/robot_import.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <sstream>

namespace ssx::detail {

namespace {

// the directories of a colon-separated list (an environment variable's), in order
std::vector<fs::path> splitPath(const char* list) {
  std::vector<fs::path> dirs;
  if (list == nullptr) return dirs;
  std::string_view s(list);
  while (!s.empty()) {
    const std::size_t colon = s.find(':');
    const std::string_view part = s.substr(0, colon);
    if (!part.empty()) dirs.emplace_back(part);
    if (colon == std::string_view::npos) break;
    s.remove_prefix(colon + 1);
  }
  return dirs;
}

bool isFile(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

void print(std::ostringstream& out, const Descriptor& d, const fs::path& dir, int depth) {
  out << std::string(2 * static_cast<std::size_t>(depth), ' ') << '<' << d.name();
  for (const auto& a : d.attributes()) {
    std::string value = a.value;
    if (d.name() == "mesh" && a.key == "file" && !dir.empty()) {
      // below the output's directory: relative to it, so that the folder moves as a whole
      std::error_code ec;
      const fs::path rel = fs::relative(fs::path(value), dir, ec);
      if (!ec && !rel.empty() && *rel.begin() != "..") value = rel.string();
    }
    out << ' ' << a.key << "=\"" << escape(value) << '"';
  }
  if (d.children().empty()) {
    out << "/>\n";
    return;
  }
  out << ">\n";
  for (const Descriptor& c : d.children()) print(out, c, dir, depth + 1);
  out << std::string(2 * static_cast<std::size_t>(depth), ' ') << "</" << d.name() << ">\n";
}

}  // namespace

fs::path ResourcePath::resolve(const std::string& uri, const fs::path& base, std::string& problem) const {
  auto scheme = [&](std::string_view prefix) { return uri.rfind(prefix, 0) == 0; };
  if (scheme("file://")) {
    const fs::path p = uri.substr(7);
    if (isFile(p)) return p;
    problem = "no file '" + p.string() + "'";
    return {};
  }
  const bool package = scheme("package://"), model = scheme("model://");
  if (!package && !model) {
    const fs::path p = fs::path(uri).is_absolute() ? fs::path(uri) : base / uri;
    if (isFile(p)) return p.lexically_normal();
    problem = "no file '" + p.lexically_normal().string() + "' (a relative path is relative to the description)";
    return {};
  }
  const std::string rest = uri.substr(package ? 10 : 8);
  const std::size_t slash = rest.find('/');
  const std::string name = rest.substr(0, slash), inside = slash == std::string::npos ? "" : rest.substr(slash + 1);
  std::vector<fs::path> search = dirs;
  for (const char* var : {"SSX_RESOURCE_PATH", package ? "ROS_PACKAGE_PATH" : "GZ_SIM_RESOURCE_PATH"})
    for (const fs::path& d : splitPath(std::getenv(var))) search.push_back(d);
  // a ROS package's folder may be the directory listed itself, or a folder in it
  for (const fs::path& d : search) {
    if (isFile(d / name / inside)) return (d / name / inside).lexically_normal();
    if (d.filename() == name && isFile(d / inside)) return (d / inside).lexically_normal();
  }
  // a model folder holding the description itself
  if (base.filename() == name && isFile(base / inside)) return (base / inside).lexically_normal();
  std::string looked;
  for (const fs::path& d : search) looked += (looked.empty() ? "" : ", ") + d.string();
  problem = "'" + name + "/" + inside + "' not found (looked in " + (looked.empty() ? std::string("no directory") : looked) +
            "; SSX_RESOURCE_PATH and " + (package ? "ROS_PACKAGE_PATH" : "GZ_SIM_RESOURCE_PATH") +
            " list where to look, separated by ':')";
  return {};
}

void setPoseAttributes(Descriptor& d, const Pose& p) {
  if (p.position != Vec3::Zero()) d.set("xyz", p.position);
  // roll, pitch, yaw about the fixed axes (x, then y, then z), as URDF and ssx write them
  const Mat3 r = p.orientation.normalized().toRotationMatrix();
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  double roll, yaw;
  if (std::abs(r(2, 0)) < 1 - 1e-12) {
    roll = std::atan2(r(2, 1), r(2, 2));
    yaw = std::atan2(r(1, 0), r(0, 0));
  } else {  // (pitch +-90 degrees: roll and yaw turn about the same axis; all of it in yaw)
    roll = 0;
    yaw = std::atan2(-r(0, 1), r(1, 1));
  }
  // (what the conversion leaves of a zero angle, a few ulps, is zero)
  Vec3 rpy(roll, pitch, yaw);
  for (int k = 0; k < 3; ++k)
    if (std::abs(rpy[k]) < 1e-12) rpy[k] = 0;
  if (rpy != Vec3::Zero()) d.set("rpy", rpy);
}

void setInertial(Descriptor& d, double mass, const Mat3& j, const Vec3& com) {
  d.set("mass", mass);
  if (com != Vec3::Zero()) d.set("com", com);
  d.set("inertia", Vec3(j(0, 0), j(1, 1), j(2, 2)));
  if (j(0, 1) != 0 || j(0, 2) != 0 || j(1, 2) != 0) d.set("inertia_products", Vec3(j(0, 1), j(0, 2), j(1, 2)));
}

void setJoint(Descriptor& n, const ImportedJoint& j, const SourceLocation& where, DiagnosticLog& log) {
  const std::string who = "joint '" + j.name + "'";
  if (j.kind == ImportedJoint::Kind::Ball) {
    n.set("joint", "ball");
    if (j.damping > 0 || j.friction > 0 || j.effort > 0)
      log.warning(where, who + ": a ball joint turns freely in ssx (its damping, friction and effort are not read)");
    return;
  }
  const bool hinge = j.kind == ImportedJoint::Kind::Hinge;
  n.set("joint", hinge ? "hinge" : "slider");
  if (!(j.axis.norm() > 1e-12)) {
    log.error(where, who + ": its axis is zero");
    return;
  }
  n.set("axis", Vec3(j.axis.normalized()));
  if (!j.continuous && j.lower != j.upper) {
    constexpr double pi = std::numbers::pi;
    if (j.lower > j.upper) {
      log.error(where, who + ": its lower limit " + formatValue(j.lower) + " is above its upper " + formatValue(j.upper));
    } else if (hinge && (j.lower < -pi - 1e-12 || j.upper > pi + 1e-12)) {
      log.warning(where, who + ": limits [" + formatValue(j.lower) + ", " + formatValue(j.upper) +
                             "] rad reach past half a turn, which ssx's hinges do not hold: the joint turns freely");
    } else {
      n.set("lower", j.lower).set("upper", j.upper);
    }
  }
  if (j.effort > 0) n.set(hinge ? "max_torque" : "max_force", j.effort);
  if (j.velocity > 0) n.set("max_velocity", j.velocity);
  if (j.damping > 0) n.set("damping", j.damping);
  if (j.friction > 0) n.set("friction", j.friction);
}

std::string formatValue(double v) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
  return ec == std::errc() ? std::string(text, end) : std::string("nan");
}

bool isRobotDescription(const fs::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".urdf" || ext == ".sdf";
}

Descriptor importRobot(const fs::path& file, const ResourcePath& resources, std::uintmax_t max_bytes, DiagnosticLog& log) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".sdf" ? importSdf(file, resources, max_bytes, log) : importUrdf(file, resources, max_bytes, log);
}

std::string artifactXml(const Descriptor& artifact, const fs::path& dir, const std::string& comment) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n";
  std::string safe = comment;  // ("--" ends a comment)
  for (std::size_t at; (at = safe.find("--")) != std::string::npos;) safe.replace(at, 2, "- -");
  if (!safe.empty()) out << "<!-- " << safe << " -->\n";
  print(out, artifact, dir, 0);
  return out.str();
}

}  // namespace ssx::detail
