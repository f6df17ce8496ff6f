// SDFormat into an <artifact>: libsdformat (12) reads and checks the model, resolves every pose
// to the model's frame and every joint axis to its joint's frame; each link becomes a physic
// node placed where its joint is (ssx joins a child at its own origin), with its inertia, shapes
// and visuals moved into that frame. What ssx does not simulate (Gazebo plugins, sensors, other
// joint kinds) is said with the line it is on.
#include "scene/import/robot_import.hpp"

#include <ssx/error.hpp>

#include <sdf/sdf.hh>

#include <charconv>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

namespace ssx::detail {

namespace {

using Pose3 = ignition::math::Pose3d;

Pose toPose(const Pose3& p) {
  return {Vec3(p.Pos().X(), p.Pos().Y(), p.Pos().Z()), Quat(p.Rot().W(), p.Rot().X(), p.Rot().Y(), p.Rot().Z())};
}

Vec3 toVec(const ignition::math::Vector3d& v) { return {v.X(), v.Y(), v.Z()}; }

struct SdfReader {
  const fs::path& file;
  const ResourcePath& resources;
  DiagnosticLog& log;
  const sdf::Model* model = nullptr;
  std::map<std::string, const sdf::Joint*> joint_of;  // child link -> its joint
  std::map<std::string, std::vector<const sdf::Joint*>> children_of;  // parent link -> joints

  SourceLocation at(const sdf::ElementPtr& e) const {
    if (e == nullptr) return {file.string(), 0};
    const auto line = e->LineNumber();
    const std::string path = e->FilePath().empty() ? file.string() : e->FilePath();
    return {path, line ? *line : 0};
  }

  // a link's pose in the model's frame
  Pose linkPose(const sdf::Link& l) {
    Pose3 p;
    const sdf::Errors errors = l.SemanticPose().Resolve(p, "__model__");
    for (const auto& e : errors) log.error(at(l.Element()), "link '" + l.Name() + "': " + e.Message());
    return toPose(p);
  }

  Pose jointPose(const sdf::Joint& j) {
    Pose3 p;
    const sdf::Errors errors = j.SemanticPose().Resolve(p, "__model__");
    for (const auto& e : errors) log.error(at(j.Element()), "joint '" + j.Name() + "': " + e.Message());
    return toPose(p);
  }

  // a geometry as ssx's shape element posed by `pose` (in the node's frame)
  std::optional<Descriptor> shape(const sdf::Geometry& g, const Pose& pose, const SourceLocation& where,
                                  const std::string& link) {
    std::optional<Descriptor> d;
    switch (g.Type()) {
      case sdf::GeometryType::BOX:
        d.emplace("box", where).set("size", toVec(g.BoxShape()->Size()));
        break;
      case sdf::GeometryType::SPHERE:
        d.emplace("sphere", where).set("radius", g.SphereShape()->Radius());
        break;
      case sdf::GeometryType::CYLINDER:
        d.emplace("cylinder", where).set("radius", g.CylinderShape()->Radius()).set("length", g.CylinderShape()->Length());
        break;
      case sdf::GeometryType::CAPSULE:
        d.emplace("capsule", where).set("radius", g.CapsuleShape()->Radius()).set("length", g.CapsuleShape()->Length());
        break;
      case sdf::GeometryType::MESH: {
        const sdf::Mesh& m = *g.MeshShape();
        if (!m.Submesh().empty())
          log.warning(where, "link '" + link + "': <submesh> is not read: the whole mesh is used");
        std::string problem;
        const fs::path base = m.FilePath().empty() ? file.parent_path() : fs::path(m.FilePath()).parent_path();
        const fs::path path = resources.resolve(m.Uri(), base, problem);
        if (path.empty()) {
          log.error(where, "link '" + link + "': mesh '" + m.Uri() + "': " + problem);
          return std::nullopt;
        }
        d.emplace("mesh", where).set("file", fs::absolute(path).lexically_normal().string());
        if (toVec(m.Scale()) != Vec3::Ones()) d->set("scale", toVec(m.Scale()));
        break;
      }
      default:
        log.warning(where, "link '" + link + "': a geometry ssx does not have (plane, heightmap, ellipsoid) is "
                           "left out; use a box, sphere, cylinder, capsule or mesh");
        return std::nullopt;
    }
    setPoseAttributes(*d, pose);
    return d;
  }

  // the link, in the frame `frame` (model frame), and the links its joints hold
  Descriptor link(const sdf::Link& l, const Pose& frame, const sdf::Joint* joint, Descriptor& artifact, int depth) {
    Descriptor n("physic", at(l.Element()));
    n.set("name", l.Name());
    const Pose in_frame = frame.inverse() * linkPose(l);  // the link's own frame in the node's
    const ignition::math::Inertiald& in = l.Inertial();
    const double mass = in.MassMatrix().Mass();
    if (mass > 0) {
      const auto& moi = in.MassMatrix().Moi();
      Mat3 j;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) j(r, c) = moi(r, c);
      const Pose inertial = in_frame * toPose(in.Pose());  // inertial frame in the node's
      const Mat3 rot = inertial.orientation.toRotationMatrix();
      setInertial(n, mass, rot * j * rot.transpose(), inertial.position);
    }
    for (std::uint64_t i = 0; i < l.CollisionCount(); ++i) {
      const sdf::Collision& c = *l.CollisionByIndex(i);
      Pose3 p;
      c.SemanticPose().Resolve(p, l.Name());
      if (c.Geom() != nullptr)
        if (auto s = shape(*c.Geom(), in_frame * toPose(p), at(c.Element()), l.Name())) n.addChild(std::move(*s));
    }
    // visuals: drawn following this node
    Descriptor r("render", at(l.Element()));
    r.set("follow", l.Name());
    for (std::uint64_t i = 0; i < l.VisualCount(); ++i) {
      const sdf::Visual& v = *l.VisualByIndex(i);
      Pose3 p;
      v.SemanticPose().Resolve(p, l.Name());
      if (v.Geom() == nullptr) continue;
      auto s = shape(*v.Geom(), in_frame * toPose(p), at(v.Element()), l.Name());
      if (!s) continue;
      if (const sdf::Material* m = v.Material()) {
        const auto c = m->Diffuse();
        s->set("color", number(c.R()) + " " + number(c.G()) + " " + number(c.B()) + " " + number(c.A()));
      }
      r.addChild(std::move(*s));
    }
    if (!r.children().empty()) artifact.addChild(std::move(r));
    for (std::uint64_t i = 0; i < l.SensorCount(); ++i) {
      const sdf::Sensor& s = *l.SensorByIndex(i);
      log.warning(at(s.Element()), "link '" + l.Name() + "': <sensor name=\"" + s.Name() + "\" type=\"" + s.TypeStr() +
                                       "\"> is Gazebo's and is not read; attach ssx's sensors in the scene's <type>");
    }
    if (joint != nullptr) jointAttributes(n, *joint);
    if (depth >= 60) {
      log.error(at(l.Element()), "link '" + l.Name() + "': the kinematic chain is deeper than 60 links");
      return n;
    }
    for (const sdf::Joint* cj : children_of[l.Name()]) {
      const sdf::Link* child = model->LinkByName(cj->ChildLinkName());
      if (child == nullptr) continue;
      const Pose child_frame = cj->Type() == sdf::JointType::FIXED ? linkPose(*child) : jointPose(*cj);
      Descriptor c = link(*child, child_frame, cj, artifact, depth + 1);
      setPoseAttributes(c, frame.inverse() * child_frame);
      n.addChild(std::move(c));
    }
    return n;
  }

  static std::string number(double v) {
    char text[32];
    const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
    return ec == std::errc() ? std::string(text, end) : std::string("nan");
  }

  void jointAttributes(Descriptor& n, const sdf::Joint& j) {
    const SourceLocation where = at(j.Element());
    ImportedJoint out;
    out.name = j.Name();
    switch (j.Type()) {
      case sdf::JointType::REVOLUTE: out.kind = ImportedJoint::Kind::Hinge; break;
      case sdf::JointType::CONTINUOUS: out.kind = ImportedJoint::Kind::Hinge; out.continuous = true; break;
      case sdf::JointType::PRISMATIC: out.kind = ImportedJoint::Kind::Slider; break;
      case sdf::JointType::FIXED: return;  // part of its parent's body
      case sdf::JointType::BALL: out.kind = ImportedJoint::Kind::Ball; break;
      default:
        log.error(where, "joint '" + j.Name() + "': ssx simulates revolute, continuous, prismatic, ball and fixed joints; "
                         "make it one of them (a universal joint: two revolute joints through a massless link)");
        return;
    }
    if (const sdf::JointAxis* a = j.Axis(0); a != nullptr && out.kind != ImportedJoint::Kind::Ball) {
      ignition::math::Vector3d xyz;
      for (const auto& e : a->ResolveXyz(xyz, j.Name())) log.error(where, "joint '" + j.Name() + "': " + e.Message());
      out.axis = toVec(xyz);
      // SDFormat's defaults for "no limit" are +-1e16
      if (!out.continuous && std::abs(a->Lower()) < 1e15 && std::abs(a->Upper()) < 1e15) {
        out.lower = a->Lower();
        out.upper = a->Upper();
      }
      if (a->Effort() > 0 && std::isfinite(a->Effort()) && a->Effort() < 1e15) out.effort = a->Effort();
      if (a->MaxVelocity() > 0 && std::isfinite(a->MaxVelocity()) && a->MaxVelocity() < 1e15) out.velocity = a->MaxVelocity();
      out.damping = a->Damping();
      out.friction = a->Friction();
      if (a->SpringStiffness() != 0)
        log.warning(where, "joint '" + j.Name() + "': its spring (<spring_stiffness>) is not simulated");
    }
    if (j.Axis(1) != nullptr) log.warning(where, "joint '" + j.Name() + "': a second axis is not read");
    setJoint(n, out, where, log);
  }

  // Gazebo's plugins (model and link level) and the like: listed, not silently dropped
  void listPlugins(const sdf::ElementPtr& e) {
    if (e == nullptr) return;
    for (sdf::ElementPtr c = e->GetFirstElement(); c != nullptr; c = c->GetNextElement()) {
      if (c->GetName() == "plugin") {
        const std::string name = c->HasAttribute("name") ? c->GetAttribute("name")->GetAsString() : "";
        const std::string lib = c->HasAttribute("filename") ? c->GetAttribute("filename")->GetAsString() : "";
        log.warning(at(c), "<plugin filename=\"" + lib + "\" name=\"" + name +
                               "\">: a Gazebo plugin is not run by ssx; attach ssx's driver and sensors in the "
                               "scene's <type> (docs/robots.md)");
      } else if (c->GetName() == "link" || c->GetName() == "joint") {
        listPlugins(c);
      }
    }
  }
};

}  // namespace

Descriptor importSdf(const fs::path& file, const ResourcePath& resources, std::uintmax_t max_bytes, DiagnosticLog& log) {
  Descriptor artifact("artifact", {file.string(), 1});
  std::string text;
  try {
    text = readInputFile(file, max_bytes);  // (bounded and a regular file, as every input)
    (void)parseXml(text, file.string());    // well-formed, with the line of what is not
  } catch (const ConfigError& e) {
    log.error(e.where(), e.detail());
    return artifact;
  }
  sdf::Root root;
  sdf::ParserConfig config;
  // includes are not followed: a model is one file (and its meshes)
  config.SetFindCallback([](const std::string&) { return std::string(); });
  const sdf::Errors errors = root.LoadSdfString(text, config);
  for (const sdf::Error& e : errors) {
    const int line = e.LineNumber() ? *e.LineNumber() : 1;
    log.error({file.string(), line}, "libsdformat: " + e.Message());
  }
  if (!errors.empty()) return artifact;
  const sdf::Model* model = root.Model();
  if (model == nullptr && root.WorldCount() > 0 && root.WorldByIndex(0)->ModelCount() > 0) {
    model = root.WorldByIndex(0)->ModelByIndex(0);
    log.warning({file.string(), 1}, "the file holds a <world>: its first model ('" + model->Name() +
                                        "') is read, the rest of the world is not (place it in an ssx scene)");
  }
  if (model == nullptr) {
    log.error({file.string(), 1}, "no <model> in the file (a robot description is one <model>)");
    return artifact;
  }
  if (model->ModelCount() > 0)
    log.warning({file.string(), 1}, "model '" + model->Name() + "': its nested models are not read");
  SdfReader r{file, resources, log, model, {}, {}};
  for (std::uint64_t i = 0; i < model->JointCount(); ++i) {
    const sdf::Joint* j = model->JointByIndex(i);
    r.joint_of[j->ChildLinkName()] = j;
    r.children_of[j->ParentLinkName()].push_back(j);
  }
  r.listPlugins(model->Element());
  std::vector<Descriptor> roots;
  for (std::uint64_t i = 0; i < model->LinkCount(); ++i) {
    const sdf::Link& l = *model->LinkByIndex(i);
    const auto it = r.joint_of.find(l.Name());
    const bool to_world = it != r.joint_of.end() && it->second->ParentLinkName() == "world";
    if (it != r.joint_of.end() && !to_world) continue;  // a child: reached from its parent
    if (to_world && it->second->Type() != sdf::JointType::FIXED) {
      log.error(r.at(it->second->Element()), "joint '" + it->second->Name() + "': a joint to the world must be fixed");
      continue;
    }
    const Pose frame = r.linkPose(l);
    Descriptor d = r.link(l, frame, nullptr, artifact, 0);
    setPoseAttributes(d, frame);
    if (model->Static() || to_world) d.set("static", true);
    roots.push_back(std::move(d));
  }
  // (SDFormat gives a link without <inertial> 1 kg and a unit inertia, as Gazebo simulates it: said)
  for (std::uint64_t i = 0; i < model->LinkCount(); ++i) {
    const sdf::Link& l = *model->LinkByIndex(i);
    if (!model->Static() && l.Element() != nullptr && !l.Element()->HasElement("inertial"))
      log.warning(r.at(l.Element()), "link '" + l.Name() + "' has no <inertial>: SDFormat's default (1 kg, inertia 1 kg "
                                     "m^2 about each axis) is used, as Gazebo uses it; give it an <inertial>");
  }
  auto& children = artifact.children();
  children.insert(children.begin(), std::make_move_iterator(roots.begin()), std::make_move_iterator(roots.end()));
  return artifact;
}

}  // namespace ssx::detail
