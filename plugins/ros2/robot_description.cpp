// A robot's URDF, written from the artifact (robot_description.hpp).
#include "robot_description.hpp"

#include "../bridge/frames.hpp"

#include <ssx/physic_node.hpp>
#include <ssx/render.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

namespace ssx::ros2 {

using bridge::linkName;

namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

std::string triple(const Vec3& v) { return number(v.x()) + " " + number(v.y()) + " " + number(v.z()); }

// <origin xyz rpy>: URDF's fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll))
std::string origin(const Pose& p) {
  const Mat3 r = p.orientation.toRotationMatrix();
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  double roll = 0, yaw = 0;
  if (std::abs(r(2, 0)) < 1 - 1e-12) {
    roll = std::atan2(r(2, 1), r(2, 2));
    yaw = std::atan2(r(1, 0), r(0, 0));
  } else {  // (gimbal lock: the yaw carries it all)
    yaw = std::atan2(-r(0, 1), r(1, 1));
  }
  return "<origin xyz=\"" + triple(p.position) + "\" rpy=\"" + triple(Vec3(roll, pitch, yaw)) + "\"/>";
}

// XML's special characters in a name or a path
std::string escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
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

// (each visual's material named apart: RViz takes two materials of one name for one)
struct Out {
  std::ostringstream text;
  int materials = 0;
};

void visual(Out& out, const Pose& at, const std::string& geometry, const Color& color) {
  out.text << "    <visual>\n      " << origin(at) << "\n      <geometry>" << geometry << "</geometry>\n"
           << "      <material name=\"ssx_" << out.materials++ << "\"><color rgba=\"" << number(color[0]) << ' '
           << number(color[1]) << ' ' << number(color[2]) << ' ' << number(color[3]) << "\"/></material>\n    </visual>\n";
}

// a render tree's shapes, each posed in the link's frame
void visuals(Out& out, const RenderNodeSpec& n, const Pose& parent) {
  const Pose at = parent * n.pose;
  using P = RenderNodeSpec::Primitive;
  switch (n.primitive) {
    case P::Box: visual(out, at, "<box size=\"" + triple(n.size) + "\"/>", n.color); break;
    case P::Sphere: visual(out, at, "<sphere radius=\"" + number(n.radius) + "\"/>", n.color); break;
    case P::Cylinder:
      visual(out, at, "<cylinder radius=\"" + number(n.radius) + "\" length=\"" + number(n.length) + "\"/>", n.color);
      break;
    case P::Capsule: {
      visual(out, at, "<cylinder radius=\"" + number(n.radius) + "\" length=\"" + number(n.length) + "\"/>", n.color);
      for (const double end : {-0.5, 0.5})
        visual(out, at * Pose{Vec3(0, 0, end * n.length), Quat::Identity()},
               "<sphere radius=\"" + number(n.radius) + "\"/>", n.color);
      break;
    }
    case P::Mesh:
      if (n.mesh != nullptr)
        visual(out, at, "<mesh filename=\"file://" + escaped(n.mesh->file) + "\" scale=\"" + triple(n.mesh->scale) + "\"/>",
               n.color);
      break;
    case P::Plane:
    case P::None: break;
  }
  for (const RenderNodeSpec& c : n.children) visuals(out, c, at);
}

}  // namespace

std::string robotDescription(const Artifact& a) {
  Out written;
  std::ostringstream& out = written.text;
  out << "<?xml version=\"1.0\"?>\n<!-- written by ssx from artifact '" << escaped(a.name())
      << "': links are its physic nodes, named as /tf names them -->\n<robot name=\"" << escaped(a.name()) << "\">\n";
  // each node's link with the render trees that follow it
  std::map<std::string, std::vector<const RenderNodeSpec*>> followers;
  for (const auto& tree : a.renderRoots())
    if (!tree->follow.empty()) followers[tree->follow].push_back(tree.get());
  for (std::size_t k = 0; k < a.nodeCount(); ++k) {
    const PhysicNode& n = a.nodeAt(k);
    out << "  <link name=\"" << escaped(linkName(a, n)) << "\">\n";
    if (const auto it = followers.find(n.name()); !n.name().empty() && it != followers.end())
      for (const RenderNodeSpec* tree : it->second) visuals(written, *tree, Pose{});
    out << "  </link>\n";
  }
  // each node's joint to its parent (a second root of the artifact hangs from the root, floating)
  for (std::size_t k = 0; k < a.nodeCount(); ++k) {
    const PhysicNode& n = a.nodeAt(k);
    if (&n == &a.root()) continue;
    const JointSpec& j = n.joint();
    const PhysicNode* parent = n.parent();
    std::string type = "fixed";
    if (parent == nullptr || j.kind == JointSpec::Kind::Ball) type = "floating";
    else if (j.kind == JointSpec::Kind::Slider) type = "prismatic";
    else if (j.kind == JointSpec::Kind::Hinge) type = std::isfinite(j.lower) && std::isfinite(j.upper) ? "revolute" : "continuous";
    const std::string name = linkName(a, n);
    out << "  <joint name=\"" << escaped(name) << "_joint\" type=\"" << type << "\">\n    <parent link=\""
        << escaped(linkName(a, parent != nullptr ? *parent : a.root())) << "\"/>\n    <child link=\"" << escaped(name)
        << "\"/>\n    " << origin(parent != nullptr ? n.spec().pose : Pose{}) << "\n";
    if (j.hasPosition()) {
      out << "    <axis xyz=\"" << triple(j.axis) << "\"/>\n";
      if (type != "continuous")
        out << "    <limit lower=\"" << number(std::isfinite(j.lower) ? j.lower : -1e9) << "\" upper=\""
            << number(std::isfinite(j.upper) ? j.upper : 1e9) << "\" effort=\"" << number(j.max_effort)
            << "\" velocity=\"" << number(std::isfinite(j.max_velocity) ? j.max_velocity : 1e9) << "\"/>\n";
    }
    out << "  </joint>\n";
  }
  out << "</robot>\n";
  return out.str();
}

}  // namespace ssx::ros2
