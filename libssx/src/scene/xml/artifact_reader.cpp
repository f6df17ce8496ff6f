// Artifact files: physic and render node trees, shapes, and the driver and sensors they declare.
#include "scene/import/robot_import.hpp"
#include "scene/xml/scene_loader.hpp"
#include "scene/xml/xml_reader.hpp"

#include <set>

namespace ssx::detail {

Shape SceneLoader::readShape(const Descriptor& d, Vec3* xyz_out, Vec3* rpy_out) {
  Shape s;
  const std::string& n = d.name();
  if (n == "box") {
    s = Shape::box(read<Vec3>(d, "size", Vec3::Ones()));
    if (!d.has("size")) error(d.where(), "<box>: missing attribute 'size'");
  } else if (n == "sphere") {
    s = Shape::sphere(readPositive(d, "radius", 0.5));
  } else {
    const double r = readPositive(d, "radius", 0.5);
    const double l = n == "cylinder" ? readPositive(d, "length", 1.0) : read<double>(d, "length", 0.0);
    s = n == "cylinder" ? Shape::cylinder(r, l) : Shape::capsule(r, l);
    if (n == "capsule" && l < 0) error(d.where(), "<capsule>: length must not be negative");
  }
  if (n == "box" && !(s.size.array() > 0).all()) error(d.where(), "<box>: every size must be positive");
  const Vec3 xyz = read<Vec3>(d, "xyz", Vec3::Zero()), rpy = read<Vec3>(d, "rpy", Vec3::Zero());
  s.pose = poseFromXyzRpy(xyz, rpy);
  if (xyz_out != nullptr) *xyz_out = xyz;
  if (rpy_out != nullptr) *rpy_out = rpy;
  s.density = readPositive(d, "density", s.density);
  checkUnknown(d);
  return s;
}

std::shared_ptr<const TriangleMesh> SceneLoader::readMesh(const Descriptor& d, bool collides) {
  const std::string file = require(d, "file");
  const Vec3 scale = read<Vec3>(d, "scale", Vec3::Ones());
  if (file.empty()) return nullptr;
  if (!scale.allFinite() || (scale.array() == 0).any()) {
    error(d.where(), "<mesh>: every scale must be finite and non-zero");
    return nullptr;
  }
  const fs::path path = resolve(artifact_dir_, file);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    error(d.where(), "<mesh>: no file '" + path.string() + "' (a relative path is relative to the artifact file)");
    return nullptr;
  }
  if (const auto bytes = fs::file_size(path, ec); !ec && bytes > options_.max_input_bytes) {
    error(d.where(), "<mesh>: '" + path.string() + "' is " + std::to_string(bytes >> 20) + " MB, larger than the " +
                         std::to_string(options_.max_input_bytes >> 20) + " MB a file read may be (--max-input-mb)");
    return nullptr;
  }
  std::string problem;
  auto mesh = meshes_.load(path, scale, problem);
  if (mesh == nullptr) {
    error(d.where(), "<mesh>: '" + path.string() + "': " + problem);
  } else if (collides && mesh->hull_triangles.empty()) {
    error(d.where(), "<mesh>: '" + path.string() + "' encloses no volume (its points lie in a plane or on a line): "
                     "it cannot be a body's shape; give the node a box or another primitive");
    return nullptr;
  }
  if (mesh != nullptr && std::find(model_.files.begin(), model_.files.end(), path) == model_.files.end())
    model_.files.push_back(path);
  return mesh;
}

void SceneLoader::readJoint(const Descriptor& d, JointSpec& j) {
  const std::string kind = read<std::string>(d, "joint", "");
  static const std::map<std::string, JointSpec::Kind> kinds = {{"hinge", JointSpec::Kind::Hinge},
                                                               {"slider", JointSpec::Kind::Slider},
                                                               {"ball", JointSpec::Kind::Ball},
                                                               {"fixed", JointSpec::Kind::Fixed}};
  if (!kind.empty()) {
    const auto it = kinds.find(kind);
    if (it == kinds.end())
      error(d.where(), "<physic>: joint must be hinge, slider, ball or fixed, got '" + kind + "'");
    else
      j.kind = it->second;
  }
  for (const char* key : {"axis", "lower", "upper", "damping", "max_torque", "max_force", "max_velocity", "friction"})
    if (d.has(key) && !j.hasPosition()) {
      error(d.where(), std::string("<physic>: '") + key + "' belongs to a hinge or slider joint" +
                           (kind.empty() ? " (this node has no joint attribute)" : ", and this joint is a " + kind));
      return;
    }
  const Vec3 axis = read<Vec3>(d, "axis", Vec3::UnitZ());
  if (!axis.allFinite() || !(axis.norm() > 1e-9))
    error(d.where(), "<physic>: axis must be a non-zero vector (the joint's axis in this node's frame)");
  else
    j.axis = axis.normalized();
  j.lower = read<double>(d, "lower", j.lower);
  j.upper = read<double>(d, "upper", j.upper);
  j.damping = read<double>(d, "damping", 0.0);
  const char* motor = j.kind == JointSpec::Kind::Slider ? "max_force" : "max_torque";
  const char* other = j.kind == JointSpec::Kind::Slider ? "max_torque" : "max_force";
  if (d.has(other))
    error(d.where(), std::string("<physic>: a ") + kind + "'s motor takes " + motor + ", not " + other);
  j.max_effort = read<double>(d, motor, 0.0);
  j.max_velocity = read<double>(d, "max_velocity", j.max_velocity);
  j.friction = read<double>(d, "friction", 0.0);
}

namespace {

// the physic node named `name` anywhere in an artifact document; every node's name into `names`
Descriptor* findPhysic(Descriptor& d, const std::string& name, std::vector<std::string>& names) {
  Descriptor* found = nullptr;
  for (Descriptor& c : d.children()) {
    if (c.name() != "physic") continue;
    if (const auto* a = c.find("name")) {
      names.push_back(a->value);
      if (a->value == name && found == nullptr) found = &c;
    }
    if (Descriptor* below = findPhysic(c, name, names); below != nullptr && found == nullptr) found = below;
  }
  return found;
}

}  // namespace

void SceneLoader::setJoint(const Descriptor& setting, Descriptor& document) {
  static const std::set<std::string> kSettings = {"max_torque", "max_force", "max_velocity", "damping",
                                                  "friction",   "lower",     "upper"};
  const std::string node = require(setting, "node");
  if (node.empty()) return;
  std::vector<std::string> names;
  Descriptor* target = findPhysic(document, node, names);
  if (target == nullptr) {
    const std::string nearest = nearestName(node, names);
    error(setting.where(), "<joint>: the type's file has no physic node '" + node + "'" +
                               (nearest.empty() ? std::string() : " (did you mean '" + nearest + "'?)"));
    return;
  }
  for (const auto& a : setting.attributes()) {
    if (a.key == "node") continue;
    a.used = true;
    if (!kSettings.contains(a.key)) {
      error(a.where, "<joint>: '" + a.key +
                         "' is not a joint setting (give max_torque, max_force, max_velocity, damping, friction, "
                         "lower or upper)");
      continue;
    }
    target->set(a.key, a.value, a.where);
  }
}

PhysicNodeSpec SceneLoader::readPhysicNode(const Descriptor& d) {
  PhysicNodeSpec n;
  n.where = d.where();
  n.name = read<std::string>(d, "name", "");
  n.pose = readPose(d);
  n.mass = readOptional<double>(d, "mass");
  if (auto diag = readOptional<Vec3>(d, "inertia")) {
    Mat3 j = diag->asDiagonal();
    const Vec3 products = read<Vec3>(d, "inertia_products", Vec3::Zero());  // ixy ixz iyz
    j(0, 1) = j(1, 0) = products.x();
    j(0, 2) = j(2, 0) = products.y();
    j(1, 2) = j(2, 1) = products.z();
    n.inertia = j;
  }
  n.center_of_mass = read<Vec3>(d, "com", Vec3::Zero());
  n.is_static = read<bool>(d, "static", false);  // validatePhysicTree refuses it below the root
  readJoint(d, n.joint);
  for (const Descriptor& c : d.children()) {
    if (kShapeElements.contains(c.name())) {
      n.shapes.push_back(readShape(c));
    } else if (c.name() == "mesh") {
      Shape s = Shape::fromMesh(readMesh(c, true), readPose(c));
      s.density = readPositive(c, "density", s.density);
      checkUnknown(c);
      if (s.mesh != nullptr) n.shapes.push_back(std::move(s));
    } else if (c.name() == "physic") {
      n.children.push_back(readPhysicNode(c));
    }
  }
  std::set<std::string> allowed = kShapeElements;
  allowed.insert({"physic", "mesh"});
  checkUnknown(d, allowed);
  return n;
}

RenderNodeSpec SceneLoader::readRenderNode(const Descriptor& d, bool is_root) {
  RenderNodeSpec n;
  n.name = read<std::string>(d, "name", "");
  n.pose = readPose(d);
  n.color = readColor(d, n.color);
  if (is_root) n.follow = read<std::string>(d, "follow", "");
  const std::string& kind = d.name();
  if (kind == "box") {
    n.primitive = RenderNodeSpec::Primitive::Box;
    n.size = read<Vec3>(d, "size", Vec3::Ones());
  } else if (kind == "sphere") {
    n.primitive = RenderNodeSpec::Primitive::Sphere;
    n.radius = readPositive(d, "radius", 0.5);
  } else if (kind == "cylinder" || kind == "capsule") {
    n.primitive = kind == "cylinder" ? RenderNodeSpec::Primitive::Cylinder : RenderNodeSpec::Primitive::Capsule;
    n.radius = readPositive(d, "radius", 0.5);
    n.length = readPositive(d, "length", 1.0);
  } else if (kind == "plane") {
    n.primitive = RenderNodeSpec::Primitive::Plane;
    n.size = read<Vec3>(d, "size", Vec3(10, 10, 0));
  } else if (kind == "mesh") {
    n.mesh = readMesh(d, false);
    if (n.mesh != nullptr) n.primitive = RenderNodeSpec::Primitive::Mesh;
  }
  for (const Descriptor& c : d.children())
    if (kShapeElements.contains(c.name()) || c.name() == "plane" || c.name() == "render" || c.name() == "mesh")
      n.children.push_back(readRenderNode(c, false));
  std::set<std::string> allowed = kShapeElements;
  allowed.insert({"plane", "render", "mesh"});
  checkUnknown(d, allowed);
  return n;
}

std::optional<PluginDecl> SceneLoader::readPluginDecl(const Descriptor& d) {
  PluginDecl decl;
  decl.plugin = require(d, "plugin");
  decl.class_name = read<std::string>(d, "class", decl.plugin);
  decl.period = readCount(d, "period", 1, 1);
  if (const auto* a = d.find("period")) decl.period_from = a->where;
  // the element is the parameter set, without what the loader itself reads: a plugin never
  // mistakes its period in steps for a parameter of its own (periodSteps() tells it)
  decl.params = d;
  decl.params.erase("plugin").erase("class").erase("period");
  // a plugin's own parameters are checked when it is configured; element children are not allowed
  for (const auto& c : d.children())
    warning(c.where(), "unknown element <" + c.name() + "> in <" + d.name() + "> (ignored)");
  if (decl.plugin.empty()) return std::nullopt;
  return decl;
}

ArtifactType SceneLoader::parseArtifact(const Descriptor& root) {
  ArtifactType t;
  if (root.name() != "artifact") {
    error(root.where(), "the root element of an artifact file must be <artifact>, got <" + root.name() + ">");
    t.ok = false;
    return t;
  }
  const std::size_t errors_before = log_.size();
  for (const Descriptor& c : root.children()) {
    if (c.name() == "physic") {
      PhysicNodeSpec spec = readPhysicNode(c);
      try {
        validatePhysicTree(spec);
        // a node's name is unique in its artifact: across its trees too (a second root named as a
        // node of the first)
        auto names = [](auto& self, const PhysicNodeSpec& n, std::vector<const PhysicNodeSpec*>& out) -> void {
          if (!n.name.empty()) out.push_back(&n);
          for (const auto& c : n.children) self(self, c, out);
        };
        std::vector<const PhysicNodeSpec*> mine, theirs;
        names(names, spec, mine);
        for (const auto& other : t.physic) names(names, *other, theirs);
        for (const PhysicNodeSpec* n : mine)
          for (const PhysicNodeSpec* o : theirs)
            if (n->name == o->name)
              throw ConfigError(n->where, "physic node '" + n->name + "': duplicate node name in this artifact");
      } catch (const ConfigError& e) {
        record(e);
      }
      t.physic.push_back(std::make_shared<const PhysicNodeSpec>(std::move(spec)));
    } else if (c.name() == "render") {
      t.render.push_back(std::make_shared<const RenderNodeSpec>(readRenderNode(c, true)));
    } else if (c.name() == "driver") {
      if (t.driver) {
        error(c.where(), "<driver>: an artifact has at most one driver");
        continue;
      }
      t.driver = readPluginDecl(c);
    } else if (c.name() == "sensor") {
      if (auto decl = readPluginDecl(c)) t.sensors.push_back(std::move(*decl));
    }
  }
  // render roots follow physic nodes by name
  for (std::size_t i = 0; i < t.render.size(); ++i) {
    const std::string& follow = t.render[i]->follow;
    if (follow.empty()) continue;
    bool found = false;
    auto search = [&](auto& self, const PhysicNodeSpec& n) -> void {
      found = found || n.name == follow;
      for (const auto& c : n.children) self(self, c);
    };
    for (const auto& p : t.physic) search(search, *p);
    if (!found) {
      const Descriptor& rd = *root.childrenNamed("render")[i];
      error(rd.where(), "<render>: follows unknown physic node '" + follow + "'");
    }
  }
  checkUnknown(root, {"physic", "render", "driver", "sensor"});
  for (std::size_t i = errors_before; i < log_.size(); ++i)
    if (log_[i].severity == Diagnostic::Severity::Error) t.ok = false;
  return t;
}

const ArtifactType* SceneLoader::artifactType(const std::string& name, const SourceLocation& where) {
  if (auto it = types_.find(name); it != types_.end()) return it->second.ok ? &it->second : nullptr;
  const auto decl = type_decls_.find(name);
  if (decl == type_decls_.end()) {
    std::string known;
    for (const auto& [k, v] : type_decls_) known += (known.empty() ? "" : ", ") + k;
    error(where,
          "unknown artifact type '" + name + "' (declared with <type>: " + (known.empty() ? "none" : known) + ")");
    types_[name].ok = false;
    return nullptr;
  }
  ArtifactType& t = types_[name];
  artifact_dir_ = decl->second.file.parent_path();
  try {
    model_.files.push_back(decl->second.file);
    if (isRobotDescription(decl->second.file)) {
      // a URDF or SDF robot, in ssx's artifact form; its problems carry its own lines
      ResourcePath resources{options_.resource_path};
      const std::size_t errors_before = errorCount();
      documents_.push_back(importRobot(decl->second.file, resources, options_.max_input_bytes, log_));
      if (errorCount() != errors_before) {
        t.ok = false;
        return nullptr;
      }
    } else {
      documents_.push_back(readXmlFile(decl->second.file, options_.max_input_bytes));
    }
    // the joint settings the scene's <type> gives the file's nodes, as if the file said them
    for (const Descriptor* j : decl->second.joints) setJoint(*j, documents_.back());
    // the driver and sensors the scene's <type> gives it, after the file's own
    for (const Descriptor* p : decl->second.plugins) {
      documents_.back().addChild(*p);
      if (auto d = readPluginDecl(*p)) {
        if (p->name() == "driver") t.type_driver = *d;
        else t.type_sensors.push_back(*d);
      }
    }
    auto type_driver = std::move(t.type_driver);
    auto type_sensors = std::move(t.type_sensors);
    t = parseArtifact(documents_.back());
    t.type_driver = std::move(type_driver);
    t.type_sensors = std::move(type_sensors);
    for (const Descriptor* j : decl->second.joints) t.type_joints.push_back(*j);
    t.name = name;
    t.file = decl->second.file;
    t.where = decl->second.where;
  } catch (const ConfigError& e) {
    if (e.where().line == 0)
      error(decl->second.where, "<type>: artifact file '" + decl->second.file.string() + "': " + e.detail());
    else
      record(e);
    t.ok = false;
  }
  return t.ok ? &t : nullptr;
}

}  // namespace ssx::detail
