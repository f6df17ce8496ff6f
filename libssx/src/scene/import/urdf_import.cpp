// URDF into an <artifact>: urdfdom reads the model (links, joints, materials, the tree); the same
// file read by ssx's XML reader gives every element's line, and what urdfdom passes over without a
// word (Gazebo extensions, transmissions, unknown tags), which is reported here.
#include "scene/import/robot_import.hpp"

#include <ssx/error.hpp>
#include <ssx/scene_model.hpp>

#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <map>
#include <numbers>
#include <set>

namespace ssx::detail {

namespace {

// a colour component as urdfdom keeps it (a float), without the digits a double would add
std::string colorText(float v) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
  return ec == std::errc() ? std::string(text, end) : std::string("1");
}

// roslaunch's substitution args that xacro passes on to the launch, as roslaunch resolves them:
// `$(optenv NAME default words)` (the variable, else the default), `$(env NAME)` (the variable, an
// error when unset) and `$(find PKG)` (the package, found as package://PKG is). Any other `$(...)`
// and xacro's own `${...}` and `<xacro:...>` are errors at their line: the file needs xacro first.
// Comments are left as they are.
std::string substituteArgs(const std::string& text, const fs::path& file, DiagnosticLog& log) {
  std::string out;
  out.reserve(text.size());
  auto lineAt = [&](std::size_t at) {
    return SourceLocation{file.string(), static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n')) + 1};
  };
  const std::string run_xacro = ": this is a xacro file, not a URDF: run `xacro " + file.filename().string() +
                                " -o " + file.stem().string() + ".urdf` and import its output";
  std::size_t i = 0;
  while (i < text.size()) {
    if (text.compare(i, 4, "<!--") == 0) {
      const std::size_t end = text.find("-->", i);
      const std::size_t stop = end == std::string::npos ? text.size() : end + 3;
      out.append(text, i, stop - i);
      i = stop;
      continue;
    }
    if (text.compare(i, 7, "<xacro:") == 0) {
      log.error(lineAt(i), "<" + text.substr(i + 1, text.find_first_of(" />", i) - i - 1) + ">" + run_xacro);
      return text;
    }
    const bool dollar = text[i] == '$' && i + 1 < text.size();
    if (dollar && text[i + 1] == '{') {
      const std::size_t end = text.find('}', i);
      log.error(lineAt(i), "'" + text.substr(i, end == std::string::npos ? 2 : end + 1 - i) + "'" + run_xacro);
      return text;
    }
    if (!dollar || text[i + 1] != '(') {
      out += text[i++];
      continue;
    }
    const std::size_t end = text.find(')', i);
    if (end == std::string::npos) {
      log.error(lineAt(i), "'$(' without its ')'");
      return text;
    }
    std::istringstream words(text.substr(i + 2, end - i - 2));
    std::string command, name, rest, word;
    words >> command >> name;
    while (words >> word) rest += (rest.empty() ? "" : " ") + word;
    const char* value = name.empty() ? nullptr : std::getenv(name.c_str());
    if (command == "optenv" && !name.empty()) {
      out += value != nullptr ? value : rest;
    } else if (command == "env" && !name.empty() && rest.empty()) {
      if (value == nullptr) {
        log.error(lineAt(i), "'$(env " + name + ")': the environment variable " + name +
                                 " is not set; set it, or write the value in the file");
        return text;
      }
      out += value;
    } else if (command == "find" && !name.empty() && rest.empty()) {
      out += "package://" + name;
    } else {
      log.error(lineAt(i), "'" + text.substr(i, end + 1 - i) + "': only roslaunch's $(optenv), $(env) and $(find) are "
                               "read in a URDF" + run_xacro);
      return text;
    }
    i = end + 1;
  }
  return out;
}

// the elements URDF defines, by parent, as urdfdom reads them (what is not here is reported)
const std::map<std::string, std::set<std::string>> kUrdfElements = {
    {"robot", {"link", "joint", "material", "transmission", "gazebo"}},
    {"link", {"inertial", "visual", "collision"}},
    {"inertial", {"origin", "mass", "inertia"}},
    {"visual", {"origin", "geometry", "material"}},
    {"collision", {"origin", "geometry"}},
    {"geometry", {"box", "sphere", "cylinder", "mesh"}},
    {"material", {"color", "texture"}},
    {"joint", {"origin", "parent", "child", "axis", "limit", "dynamics", "mimic", "safety_controller", "calibration"}},
};

// the mass of a link and of every link fixed to it (the rigid body they make)
double fixedBodyMass(const urdf::Link& l) {
  double mass = l.inertial ? l.inertial->mass : 0.0;
  for (const auto& j : l.child_joints)
    if (j->type == urdf::Joint::FIXED)
      for (const auto& c : l.child_links)
        if (c->name == j->child_link_name) mass += fixedBodyMass(*c);
  return mass;
}

struct UrdfReader {
  const fs::path& file;
  const ResourcePath& resources;
  DiagnosticLog& log;
  std::map<std::string, const Descriptor*> link_elements, joint_elements;
  const urdf::ModelInterface* model = nullptr;
  std::string root_name;

  void error(const SourceLocation& at, const std::string& m) { log.error(at, m); }
  void warning(const SourceLocation& at, const std::string& m) { log.warning(at, m); }

  SourceLocation linkAt(const std::string& name) const {
    const auto it = link_elements.find(name);
    return it == link_elements.end() ? SourceLocation{file.string(), 0} : it->second->where();
  }
  SourceLocation jointAt(const std::string& name) const {
    const auto it = joint_elements.find(name);
    return it == joint_elements.end() ? SourceLocation{file.string(), 0} : it->second->where();
  }
  // the i-th child named `what` of a link's element, or the link's element
  SourceLocation partAt(const std::string& link, const char* what, std::size_t i) const {
    const auto it = link_elements.find(link);
    if (it == link_elements.end()) return {file.string(), 0};
    const auto parts = it->second->childrenNamed(what);
    return i < parts.size() ? parts[i]->where() : it->second->where();
  }

  // the numbers urdfdom reads, checked here where their lines are known (urdfdom prints what it
  // cannot read to the console, and may go on without the element)
  void checkNumbers(const Descriptor& d) {
    static const std::map<std::string, std::vector<std::pair<const char*, int>>> kNumbers = {
        {"origin", {{"xyz", 3}, {"rpy", 3}}}, {"mass", {{"value", 1}}},
        {"inertia", {{"ixx", 1}, {"ixy", 1}, {"ixz", 1}, {"iyy", 1}, {"iyz", 1}, {"izz", 1}}},
        {"box", {{"size", 3}}}, {"sphere", {{"radius", 1}}}, {"cylinder", {{"radius", 1}, {"length", 1}}},
        {"mesh", {{"scale", 3}}}, {"axis", {{"xyz", 3}}}, {"color", {{"rgba", 4}}},
        {"limit", {{"lower", 1}, {"upper", 1}, {"effort", 1}, {"velocity", 1}}},
        {"dynamics", {{"damping", 1}, {"friction", 1}}}};
    const auto it = kNumbers.find(d.name());
    if (it == kNumbers.end()) return;
    for (const auto& [key, count] : it->second) {
      const auto* a = d.find(key);
      if (a == nullptr) continue;
      std::istringstream in(a->value);
      int n = 0;
      bool ok = true;
      for (std::string word; in >> word; ++n) {
        char* end = nullptr;
        const double v = std::strtod(word.c_str(), &end);
        ok = ok && end == word.c_str() + word.size() && std::isfinite(v);
      }
      if (!ok || n != count)
        error(a->where, "<" + d.name() + ">: " + key + " '" + a->value + "' is not " +
                            (count == 1 ? std::string("a number") : std::to_string(count) + " numbers"));
    }
  }

  // what urdfdom does not read: listed, so that nothing is dropped without a word
  void scan(const Descriptor& d) {
    checkNumbers(d);
    const auto known = kUrdfElements.find(d.name());
    for (const Descriptor& c : d.children()) {
      if (d.name() == "robot" && c.name() == "gazebo") {
        const std::string ref = c.get<std::string>("reference", "");
        warning(c.where(), "<gazebo" + (ref.empty() ? std::string() : " reference=\"" + ref + "\"") +
                               ">: Gazebo's extension is not read by ssx (its plugins, sensors and surface "
                               "parameters are Gazebo's); attach ssx's driver and sensors in the scene's <type>");
        continue;
      }
      if (d.name() == "robot" && c.name() == "transmission") {
        warning(c.where(), "<transmission" +
                               (c.has("name") ? " name=\"" + c.get<std::string>("name", "") + "\"" : std::string()) +
                               ">: transmissions are ros_control's and are ignored; joints are driven by their "
                               "motors (max_torque / max_force from <limit effort>)");
        continue;
      }
      if (known != kUrdfElements.end() && !known->second.contains(c.name())) {
        warning(c.where(), "unknown element <" + c.name() + "> in <" + d.name() + "> (ignored, as urdfdom ignores it)");
        continue;
      }
      if (d.name() == "geometry" || !kUrdfElements.contains(c.name())) checkNumbers(c);
      else scan(c);
    }
  }

  static Vec3 vec(const urdf::Vector3& v) { return {v.x, v.y, v.z}; }
  static Pose pose(const urdf::Pose& p) {
    double x, y, z, w;
    p.rotation.getQuaternion(x, y, z, w);
    return {vec(p.position), Quat(w, x, y, z).normalized()};
  }
  static void setPose(Descriptor& d, const urdf::Pose& p) { setPoseAttributes(d, pose(p)); }
  // the pose of `owner`'s <origin>, as the file writes it (its text, so that nothing is rounded),
  // else urdfdom's
  static void setOrigin(Descriptor& d, const Descriptor* owner, const urdf::Pose& p) {
    const Descriptor* origin = owner != nullptr ? owner->child("origin") : nullptr;
    if (origin == nullptr) return setPose(d, p);
    for (const char* key : {"xyz", "rpy"}) {
      std::istringstream in(origin->get<std::string>(key, ""));
      std::string text, word;
      bool zero = true;
      while (in >> word) {
        text += (text.empty() ? "" : " ") + word;
        zero = zero && std::strtod(word.c_str(), nullptr) == 0;
      }
      if (!zero) d.set(key, text, origin->where());
    }
  }
  const Descriptor* part(const std::string& link, const char* what, std::size_t i) const {
    const auto it = link_elements.find(link);
    if (it == link_elements.end()) return nullptr;
    const auto parts = it->second->childrenNamed(what);
    return i < parts.size() ? parts[i] : nullptr;
  }
  const Descriptor* jointElement(const std::string& name) const {
    const auto it = joint_elements.find(name);
    return it == joint_elements.end() ? nullptr : it->second;
  }

  // a <geometry> as ssx's shape element (collision or visual), or nothing when it cannot be
  std::optional<Descriptor> shape(const urdf::Geometry& g, const urdf::Pose& origin, const Descriptor* element,
                                  const std::string& link) {
    const SourceLocation at = element != nullptr ? element->where() : linkAt(link);
    std::optional<Descriptor> d;
    switch (g.type) {
      case urdf::Geometry::BOX: {
        const auto& b = static_cast<const urdf::Box&>(g);
        d.emplace("box", at).set("size", vec(b.dim));
        break;
      }
      case urdf::Geometry::SPHERE:
        d.emplace("sphere", at).set("radius", static_cast<const urdf::Sphere&>(g).radius);
        break;
      case urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const urdf::Cylinder&>(g);
        d.emplace("cylinder", at).set("radius", c.radius).set("length", c.length);
        break;
      }
      case urdf::Geometry::MESH: {
        const auto& m = static_cast<const urdf::Mesh&>(g);
        std::string problem;
        const fs::path path = resources.resolve(m.filename, file.parent_path(), problem);
        if (path.empty()) {
          error(at, "link '" + link + "': mesh '" + m.filename + "': " + problem);
          return std::nullopt;
        }
        d.emplace("mesh", at).set("file", fs::absolute(path).lexically_normal().string());
        if (vec(m.scale) != Vec3::Ones()) d->set("scale", vec(m.scale));
        break;
      }
    }
    setOrigin(*d, element, origin);
    return d;
  }

  // the link and, below it, every link its joints hold
  Descriptor link(const urdf::Link& l, const urdf::Joint* parent_joint, int depth) {
    Descriptor n("physic", linkAt(l.name));
    n.set("name", l.name);
    const bool is_root = parent_joint == nullptr;
    bool moving = !is_root;
    if (parent_joint != nullptr) {
      const urdf::Joint& j = *parent_joint;
      n = Descriptor("physic", jointAt(j.name));
      n.set("name", l.name);
      setOrigin(n, jointElement(j.name), j.parent_to_joint_origin_transform);
      joint(n, j);
      moving = j.type != urdf::Joint::FIXED;
    }
    // a root whose rigid body (it and the links fixed to it) has mass 0 is fixed in the world (the
    // convention PyBullet and Bullet's URDFs follow); a massless root link carrying a body by a
    // fixed joint (a ground robot's base_footprint over its base_link) is that body's frame
    const bool massless = !l.inertial || !(l.inertial->mass > 0);
    if (is_root && !(fixedBodyMass(l) > 0)) {
      n.set("static", true);
    } else if (!massless) {
      const urdf::Inertial& in = *l.inertial;
      // the tensor in the inertial frame, turned into the link's axes
      Mat3 j;
      j << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
      const Mat3 r = pose(in.origin).orientation.toRotationMatrix();
      setInertial(n, in.mass, r * j * r.transpose(), vec(in.origin.position));
    } else if (!l.collision_array.empty()) {
      // a link without mass is given its collision shapes' (as water), and told so
      warning(linkAt(l.name), "link '" + l.name + "' has no <inertial> (or a mass of 0): its mass and inertia are "
                              "those of its collision shapes at 1000 kg/m^3; give it an <inertial>");
    } else if (moving) {
      error(linkAt(l.name), "link '" + l.name + "' moves on joint '" + parent_joint->name +
                                "' but has neither <inertial> nor <collision>: give it an <inertial> with a mass");
    }
    for (std::size_t i = 0; i < l.collision_array.size(); ++i) {
      const urdf::Collision& c = *l.collision_array[i];
      if (c.geometry)
        if (auto s = shape(*c.geometry, c.origin, part(l.name, "collision", i), l.name)) n.addChild(std::move(*s));
    }
    if (depth >= kMaxLinkDepth) {
      error(linkAt(l.name), "link '" + l.name + "': the kinematic chain is deeper than " +
                                std::to_string(kMaxLinkDepth) + " links");
      return n;
    }
    for (const auto& cj : l.child_joints) {
      const auto child = model->getLink(cj->child_link_name);
      if (child) n.addChild(link(*child, cj.get(), depth + 1));
    }
    return n;
  }

  void joint(Descriptor& n, const urdf::Joint& j) {
    const SourceLocation at = jointAt(j.name);
    const std::string who = "joint '" + j.name + "'";
    ImportedJoint out;
    out.name = j.name;
    switch (j.type) {
      case urdf::Joint::REVOLUTE: break;
      case urdf::Joint::CONTINUOUS: out.continuous = true; break;
      case urdf::Joint::PRISMATIC: out.kind = ImportedJoint::Kind::Slider; break;
      case urdf::Joint::FIXED:
        return;  // the child is part of its parent's body, as Gazebo merges fixed joints
      case urdf::Joint::FLOATING:
        error(at, who + ": floating joints are not simulated by ssx; give the child link its own robot (a "
                        "separate <type>), or make the joint fixed");
        return;
      case urdf::Joint::PLANAR:
        error(at, who + ": planar joints are not simulated by ssx; use two prismatic joints and a revolute "
                        "one through massless links");
        return;
      default:
        error(at, who + ": unknown joint type");
        return;
    }
    out.axis = vec(j.axis);
    if (j.limits) {
      if (!out.continuous) {
        out.lower = j.limits->lower;
        out.upper = j.limits->upper;
      }
      out.effort = j.limits->effort;
      out.velocity = j.limits->velocity;
    } else if (j.type == urdf::Joint::REVOLUTE) {
      warning(at, who + ": a revolute joint without <limit>: it turns freely, as a continuous one");
    }
    if (j.dynamics) {
      out.damping = j.dynamics->damping;
      out.friction = j.dynamics->friction;
    }
    setJoint(n, out, at, log);
    if (j.mimic)
      warning(at, who + ": <mimic joint=\"" + j.mimic->joint_name +
                      "\"> is ignored: ssx drives each joint by itself (command it as the other one times the multiplier)");
  }

  // every link's visuals as one render root each, following the link
  void visuals(Descriptor& artifact) {
    for (const auto& [name, l] : model->links_) {
      if (l->visual_array.empty() || (name == "world" && model->getRoot()->name == "world")) continue;
      Descriptor r("render", linkAt(name));
      r.set("follow", name);
      for (std::size_t i = 0; i < l->visual_array.size(); ++i) {
        const urdf::Visual& v = *l->visual_array[i];
        if (!v.geometry) continue;
        auto s = shape(*v.geometry, v.origin, part(name, "visual", i), name);
        if (!s) continue;
        if (v.material) {
          const urdf::Color& c = v.material->color;
          s->set("color", colorText(c.r) + " " + colorText(c.g) + " " + colorText(c.b) + " " + colorText(c.a));
          if (!v.material->texture_filename.empty())
            warning(partAt(name, "visual", i), "link '" + name + "': textures are not drawn (the material's colour is)");
        }
        r.addChild(std::move(*s));
      }
      if (!r.children().empty()) artifact.addChild(std::move(r));
    }
  }

  static constexpr int kMaxLinkDepth = 60;  // below the XML reader's nesting bound, with room
};

// what urdfdom needs to hold for its tree, checked with lines first (urdfdom only prints to the
// console and says no)
bool checkStructure(const Descriptor& robot, UrdfReader& r) {
  const std::size_t before = r.log.errorCount();
  for (const Descriptor* l : robot.childrenNamed("link")) {
    const std::string name = l->get<std::string>("name", "");
    if (name.empty()) r.error(l->where(), "<link>: missing attribute 'name'");
    else if (!r.link_elements.emplace(name, l).second)
      r.error(l->where(), "link '" + name + "' is defined twice (first at " + r.link_elements[name]->where().str() + ")");
  }
  std::map<std::string, std::string> parent_of;  // child link -> parent link
  for (const Descriptor* j : robot.childrenNamed("joint")) {
    const std::string name = j->get<std::string>("name", "");
    if (name.empty()) {
      r.error(j->where(), "<joint>: missing attribute 'name'");
      continue;
    }
    if (!r.joint_elements.emplace(name, j).second)
      r.error(j->where(), "joint '" + name + "' is defined twice");
    static const std::set<std::string> types = {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"};
    const std::string type = j->get<std::string>("type", "");
    if (!types.contains(type))
      r.error(j->where(), "joint '" + name + "': type must be revolute, continuous, prismatic, fixed, floating or "
                          "planar, got '" + type + "'");
    const Descriptor* p = j->child("parent");
    const Descriptor* c = j->child("child");
    const std::string parent = p != nullptr ? p->get<std::string>("link", "") : "";
    const std::string child = c != nullptr ? c->get<std::string>("link", "") : "";
    if (parent.empty() || child.empty()) {
      r.error(j->where(), "joint '" + name + "': needs <parent link=\"...\"/> and <child link=\"...\"/>");
      continue;
    }
    for (const std::string& l : {parent, child})
      if (!r.link_elements.contains(l)) r.error(j->where(), "joint '" + name + "': no link named '" + l + "'");
    if (const auto [it, fresh] = parent_of.emplace(child, parent); !fresh)
      r.error(j->where(), "joint '" + name + "': link '" + child + "' already has a parent ('" + it->second +
                          "'): a URDF is a tree");
  }
  // a loop: following parents from some link comes back to it
  for (const auto& [child, parent] : parent_of) {
    std::string at = parent;
    for (std::size_t n = 0; n <= parent_of.size() && parent_of.contains(at); ++n) {
      if (at == child) {
        r.error(r.linkAt(child), "link '" + child + "' is its own ancestor: the joints make a loop, and a URDF is a tree");
        break;
      }
      at = parent_of.at(at);
    }
  }
  std::vector<std::string> roots;
  for (const auto& [name, d] : r.link_elements)
    if (!parent_of.contains(name)) roots.push_back(name);
  if (r.link_elements.empty()) r.error(robot.where(), "<robot>: has no <link>");
  else if (roots.size() > 1 && r.log.errorCount() == before)
    r.error(robot.where(), "<robot>: links '" + roots[0] + "' and '" + roots[1] +
                               "' have no parent: a URDF has one root link, joined to every other");
  return r.log.errorCount() == before;
}

}  // namespace

Descriptor importUrdf(const fs::path& file, const ResourcePath& resources, std::uintmax_t max_bytes, DiagnosticLog& log) {
  Descriptor artifact("artifact", {file.string(), 1});
  UrdfReader r{file, resources, log, {}, {}, nullptr, {}};
  Descriptor robot;
  std::string text;
  try {
    text = readInputFile(file, max_bytes);
    const std::size_t errors = log.errorCount();
    text = substituteArgs(text, file, log);
    if (log.errorCount() != errors) return artifact;
    robot = parseXml(text, file.string());
  } catch (const ConfigError& e) {
    log.error(e.where(), e.detail());
    return artifact;
  }
  if (robot.name() != "robot") {
    log.error(robot.where(), "the root element of a URDF file must be <robot>, got <" + robot.name() + ">");
    return artifact;
  }
  const std::size_t errors_before = log.errorCount();
  r.scan(robot);
  if (!checkStructure(robot, r) || log.errorCount() != errors_before) return artifact;
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(text);
  } catch (const std::exception& e) {
    log.error(robot.where(), std::string("urdfdom could not read the robot: ") + e.what());
    return artifact;
  }
  if (!model) {
    log.error(robot.where(), "urdfdom could not read the robot (its message is printed above): a value it could not "
                             "parse, or a required element missing");
    return artifact;
  }
  r.model = model.get();
  const urdf::LinkConstSharedPtr root = model->getRoot();
  // a root link named "world" is the world itself (the ROS convention for a robot bolted down):
  // its children are static roots of their own
  if (root->name == "world") {
    for (const auto& cj : root->child_joints) {
      if (cj->type != urdf::Joint::FIXED) {
        log.error(r.jointAt(cj->name), "joint '" + cj->name + "': a joint to the link 'world' must be fixed (a robot "
                                       "moving over the world is placed in the scene, not joined to it)");
        continue;
      }
      Descriptor d = r.link(*model->getLink(cj->child_link_name), nullptr, 0);
      d.set("static", true);
      urdf::Pose p = cj->parent_to_joint_origin_transform;
      UrdfReader::setOrigin(d, r.jointElement(cj->name), p);
      artifact.addChild(std::move(d));
    }
  } else {
    artifact.addChild(r.link(*root, nullptr, 0));
  }
  r.visuals(artifact);
  return artifact;
}

}  // namespace ssx::detail
