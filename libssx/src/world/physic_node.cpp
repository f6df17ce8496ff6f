// PhysicNodeSpec and Shape (what a node is) and PhysicNode (a handle into the world state: reads the
// snapshot, writes its artifact's command buffer).
#include "world/phase_guard.hpp"
#include "world/world.hpp"

#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/physic_node.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>

namespace ssx {

namespace {

// the point of triangle (a, b, c) nearest to p (Ericson, Real-Time Collision Detection, 5.1.5)
Vec3 nearestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// the hull's point nearest to q (q itself inside it)
Vec3 nearestHullPoint(const TriangleMesh& m, const Vec3& q) {
  const auto& v = m.hull_vertices;
  const auto& t = m.hull_triangles;
  bool inside = !t.empty();
  Vec3 best = q;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 2 < t.size(); i += 3) {
    const Vec3 &a = v[t[i]], &b = v[t[i + 1]], &c = v[t[i + 2]];
    if ((b - a).cross(c - a).dot(q - a) > 0) inside = false;
    const Vec3 n = nearestOnTriangle(q, a, b, c);
    if (const double d = (n - q).squaredNorm(); d < best_d) {
      best_d = d;
      best = n;
    }
  }
  return inside ? q : best;
}

}  // namespace

Vec3 nearestSurfacePoint(const Shape& s, const Pose& world, const Vec3& p) {
  const Vec3 q = world.inverse().transformPoint(p);
  Vec3 n = q;
  switch (s.kind) {
    case Shape::Kind::Sphere:
      if (q.norm() > s.radius) n = q.normalized() * s.radius;
      break;
    case Shape::Kind::Box:
      n = q.cwiseMax(-s.size / 2).cwiseMin(s.size / 2);
      break;
    case Shape::Kind::Cylinder: {
      n.z() = std::clamp(q.z(), -s.length / 2, s.length / 2);
      const double r = std::hypot(q.x(), q.y());
      if (r > s.radius) n.head<2>() = q.head<2>() * (s.radius / r);
      break;
    }
    case Shape::Kind::Capsule: {
      const Vec3 axis(0, 0, std::clamp(q.z(), -s.length / 2, s.length / 2));
      const Vec3 d = q - axis;
      if (d.norm() > s.radius) n = axis + d.normalized() * s.radius;
      break;
    }
    case Shape::Kind::Plane:
      n.z() = 0;
      break;
    case Shape::Kind::Mesh:
      if (s.mesh != nullptr) n = nearestHullPoint(*s.mesh, q);
      break;
  }
  return world.transformPoint(n);
}

namespace {

constexpr double kPi = std::numbers::pi;

// adds a body of `mass` with inertia `inertia` (about its own centre `c`, axes of `total`'s frame)
// to `total`: combined centre, and both inertias moved there by the parallel-axis theorem
void addMass(MassProperties& total, double mass, const Vec3& c, const Mat3& inertia) {
  if (!(mass > 0)) return;
  const double m = total.mass + mass;
  const Vec3 com = (total.mass * total.center_of_mass + mass * c) / m;
  auto shifted = [&com](const Mat3& j, double jm, const Vec3& from) {
    const Vec3 d = from - com;
    return Mat3(j + jm * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
  };
  total.inertia = shifted(total.inertia, total.mass, total.center_of_mass) + shifted(inertia, mass, c);
  total.mass = m;
  total.center_of_mass = com;
}

// mass properties of one node alone, in its own frame
MassProperties nodeMass(const PhysicNodeSpec& node) {
  MassProperties shapes;
  for (const auto& s : node.shapes) {
    if (s.kind == Shape::Kind::Plane) continue;
    const double m = s.volume() * s.density;
    const Mat3 r = s.pose.orientation.toRotationMatrix();
    addMass(shapes, m, s.pose.transformPoint(s.centroid()), r * s.unitInertia(m) * r.transpose());
  }
  if (!node.mass) return shapes;
  if (node.inertia) return {*node.mass, node.center_of_mass, *node.inertia};
  // mass given, inertia from the shapes scaled to it
  MassProperties scaled = shapes;
  if (shapes.mass > 0) scaled.inertia *= *node.mass / shapes.mass;
  scaled.mass = *node.mass;
  return scaled;
}

// `joined`: whether the children with joints count too (the whole tree) or not (one body)
void accumulate(const PhysicNodeSpec& node, const Pose& in_root, MassProperties& total, bool joined) {
  const MassProperties own = nodeMass(node);
  const Mat3 r = in_root.orientation.toRotationMatrix();
  addMass(total, own.mass, in_root.transformPoint(own.center_of_mass), r * own.inertia * r.transpose());
  for (const auto& child : node.children)
    if (joined || !child.joint.isBody()) accumulate(child, in_root * child.pose, total, joined);
}

std::string nodeLabel(const PhysicNodeSpec& node) {
  return node.name.empty() ? std::string("physic node") : "physic node '" + node.name + "'";
}

void validateBody(const PhysicNodeSpec& root);

void validateJoint(const PhysicNodeSpec& node, bool is_root) {
  auto fail = [&](const std::string& what) { throw ConfigError(node.where, nodeLabel(node) + ": " + what); };
  const JointSpec& j = node.joint;
  if (!j.isBody()) return;
  if (is_root) fail("a root node has no parent to be joined to: give the joint to a child node");
  const std::string kind = jointKindName(j.kind);
  if (j.hasPosition()) {
    if (!j.axis.allFinite() || std::abs(j.axis.norm() - 1.0) > 1e-6)
      fail("the " + kind + "'s axis must be a unit vector (in the node's frame)");
    if (std::isnan(j.lower) || std::isnan(j.upper) || !(j.lower <= j.upper))
      fail("the " + kind + "'s limits must be in order: lower <= upper");
    if (j.kind == JointSpec::Kind::Hinge && ((std::isfinite(j.lower) && j.lower < -kPi - 1e-12) || (std::isfinite(j.upper) && j.upper > kPi + 1e-12)))
      fail("a hinge's limits must lie within [-pi, pi] rad (leave them out for a joint that turns freely)");
    if (!(std::isfinite(j.damping) && j.damping >= 0)) fail("damping must be finite and >= 0");
    if (!(std::isfinite(j.max_effort) && j.max_effort >= 0))
      fail(std::string("the motor's ") + (j.kind == JointSpec::Kind::Hinge ? "max_torque" : "max_force") +
           " must be finite and >= 0");
    if (!(j.max_velocity > 0)) fail("max_velocity must be positive (leave it out for no bound)");
    if (!(std::isfinite(j.friction) && j.friction >= 0)) fail("friction must be finite and >= 0");
  } else if (std::isfinite(j.lower) || std::isfinite(j.upper) || j.damping != 0 || j.max_effort != 0 ||
             j.friction != 0 || std::isfinite(j.max_velocity)) {
    fail("a " + kind + " joint takes no limits, damping, friction or motor (only hinges and sliders do)");
  }
  validateBody(node);
}

void validateNode(const PhysicNodeSpec& node, bool is_root, bool root_static, std::set<std::string>& names) {
  auto fail = [&](const std::string& what) { throw ConfigError(node.where, nodeLabel(node) + ": " + what); };
  if (!node.name.empty() && !names.insert(node.name).second) fail("duplicate node name in this tree");
  if (node.is_static && !is_root) fail("only a root node can be static");
  validateJoint(node, is_root);
  if (node.mass && !(std::isfinite(*node.mass) && *node.mass > 0))
    fail("mass must be positive, got " + std::to_string(*node.mass) + " kg");
  if (node.inertia) {
    if (!node.mass) fail("an inertia needs a mass");
    const Mat3& j = *node.inertia;
    if (!j.allFinite() || (j - j.transpose()).cwiseAbs().maxCoeff() > 1e-12 * j.cwiseAbs().maxCoeff())
      fail("inertia must be a finite symmetric matrix");
    const Vec3 eig = Eigen::SelfAdjointEigenSolver<Mat3>(j).eigenvalues();
    if (!(eig.minCoeff() > 0)) fail("inertia must be positive definite (principal moments > 0)");
    if (eig[0] + eig[1] < eig[2] * (1 - 1e-9))
      fail("inertia violates the triangle inequality (no rigid body has these principal moments)");
  }
  for (const auto& s : node.shapes) {
    bool ok = true;
    switch (s.kind) {
      case Shape::Kind::Box:
        ok = (s.size.array() > 0).all() && s.size.allFinite();
        break;
      case Shape::Kind::Sphere:
        ok = s.radius > 0 && std::isfinite(s.radius);
        break;
      case Shape::Kind::Cylinder:
      case Shape::Kind::Capsule:
        ok = s.radius > 0 && s.length >= 0 && std::isfinite(s.radius) && std::isfinite(s.length);
        if (s.kind == Shape::Kind::Cylinder) ok = ok && s.length > 0;
        break;
      case Shape::Kind::Plane:
        if (!(is_root && root_static)) fail("a plane shape is allowed only on a static root node");
        break;
      case Shape::Kind::Mesh:
        ok = s.mesh != nullptr && !s.mesh->triangles.empty() && (root_static || s.mesh->hull_volume > 0);
        break;
    }
    if (!ok) fail("shape sizes must be positive and finite");
    if (!(s.density > 0 && std::isfinite(s.density))) fail("shape density must be positive");
  }
  for (const auto& c : node.children) validateNode(c, false, root_static, names);
}

}  // namespace

Shape Shape::box(const Vec3& size, const Pose& pose) {
  Shape s;
  s.kind = Kind::Box;
  s.size = size;
  s.pose = pose;
  return s;
}
Shape Shape::sphere(double radius, const Pose& pose) {
  Shape s;
  s.kind = Kind::Sphere;
  s.radius = radius;
  s.pose = pose;
  return s;
}
Shape Shape::cylinder(double radius, double length, const Pose& pose) {
  Shape s;
  s.kind = Kind::Cylinder;
  s.radius = radius;
  s.length = length;
  s.pose = pose;
  return s;
}
Shape Shape::capsule(double radius, double length, const Pose& pose) {
  Shape s = cylinder(radius, length, pose);
  s.kind = Kind::Capsule;
  return s;
}
Shape Shape::plane(const Pose& pose) {
  Shape s;
  s.kind = Kind::Plane;
  s.pose = pose;
  return s;
}
Shape Shape::fromMesh(std::shared_ptr<const TriangleMesh> mesh, const Pose& pose) {
  Shape s;
  s.kind = Kind::Mesh;
  s.mesh = std::move(mesh);
  s.pose = pose;
  return s;
}

Vec3 Shape::centroid() const {
  return kind == Kind::Mesh && mesh != nullptr ? mesh->hull_centroid : Vec3::Zero();
}

double Shape::volume() const {
  switch (kind) {
    case Kind::Box:
      return size.prod();
    case Kind::Sphere:
      return 4.0 / 3.0 * kPi * radius * radius * radius;
    case Kind::Cylinder:
      return kPi * radius * radius * length;
    case Kind::Capsule:
      return kPi * radius * radius * (length + 4.0 / 3.0 * radius);
    case Kind::Plane:
      return 0.0;
    case Kind::Mesh:
      return mesh != nullptr ? mesh->hull_volume : 0.0;
  }
  return 0.0;
}

Mat3 Shape::unitInertia(double m) const {
  const double r2 = radius * radius;
  switch (kind) {
    case Kind::Box: {
      const Vec3 s2 = size.cwiseProduct(size);
      return (m / 12.0 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y())).asDiagonal();
    }
    case Kind::Sphere:
      return Mat3::Identity() * (0.4 * m * r2);
    case Kind::Cylinder: {
      const double t = m * (3 * r2 + length * length) / 12.0;
      return Vec3(t, t, 0.5 * m * r2).asDiagonal();
    }
    case Kind::Capsule: {
      // cylinder plus two hemispheres, mass split by volume
      const double vc = length;
      const double vs = 4.0 / 3.0 * radius;
      const double mc = m * vc / (vc + vs);
      const double ms = m - mc;
      const double h = length;
      const double t = mc * (h * h / 12.0 + r2 / 4.0) + ms * (0.4 * r2 + h * h / 4.0 + 3.0 * h * radius / 8.0);
      return Vec3(t, t, 0.5 * mc * r2 + 0.4 * ms * r2).asDiagonal();
    }
    case Kind::Plane:
      return Mat3::Zero();
    case Kind::Mesh:
      return mesh != nullptr ? Mat3(m * mesh->hull_unit_inertia) : Mat3::Zero();
  }
  return Mat3::Zero();
}

PhysicNodeSpec& PhysicNodeSpec::addChild(PhysicNodeSpec child) {
  children.push_back(std::move(child));
  return children.back();
}

namespace {
constexpr double kMinBodyMass = 1e-9, kMaxBodyMass = 1e9;           // kg: a microgram's thousandth, a million tonnes
constexpr double kMinBodyInertia = 1e-18, kMaxBodyInertia = 1e18;   // kg m^2
}  // namespace

namespace {

// a body's mass and inertia, as an engine steps them
void validateBody(const PhysicNodeSpec& root) {
  {
    const MassProperties m = bodyMass(root);
    if (!(m.mass > 0))
      throw ConfigError(root.where, nodeLabel(root) + ": a dynamic body needs mass: give a mass or shapes with volume");
    const Vec3 eig = Eigen::SelfAdjointEigenSolver<Mat3>(m.inertia).eigenvalues();
    if (!(eig.minCoeff() > 0))
      throw ConfigError(
          root.where,
          nodeLabel(root) + ": the body's combined inertia is singular: give an inertia or shapes with volume");
    // what the engines step: beyond these, their arithmetic loses the body (ODE asserts at step 0
    // for 1e308 kg); far beyond any robot or obstacle
    const auto beyond = [&](const std::string& what, double value, double lo, double hi, const char* unit) {
      char text[200];
      std::snprintf(text, sizeof text, ": the body's %s %.3g %s is beyond what the engines step (%.0e to %.0e %s)",
                    what.c_str(), value, unit, lo, hi, unit);
      return ConfigError(root.where, nodeLabel(root) + text);
    };
    if (m.mass < kMinBodyMass || m.mass > kMaxBodyMass) throw beyond("mass", m.mass, kMinBodyMass, kMaxBodyMass, "kg");
    if (eig.minCoeff() < kMinBodyInertia || eig.maxCoeff() > kMaxBodyInertia) {
      const double worst = eig.minCoeff() < kMinBodyInertia ? eig.minCoeff() : eig.maxCoeff();
      throw beyond("principal moment of inertia", worst, kMinBodyInertia, kMaxBodyInertia, "kg m^2");
    }
  }
}

}  // namespace

void validatePhysicTree(const PhysicNodeSpec& root) {
  std::set<std::string> names;
  validateNode(root, true, root.is_static, names);
  if (!root.is_static) validateBody(root);
}

MassProperties combinedMass(const PhysicNodeSpec& root) {
  MassProperties total;
  accumulate(root, Pose::identity(), total, true);
  return total;
}

MassProperties bodyMass(const PhysicNodeSpec& node) {
  MassProperties total;
  accumulate(node, Pose::identity(), total, false);
  return total;
}

const char* jointKindName(JointSpec::Kind kind) {
  switch (kind) {
    case JointSpec::Kind::Rigid: return "rigid";
    case JointSpec::Kind::Hinge: return "hinge";
    case JointSpec::Kind::Slider: return "slider";
    case JointSpec::Kind::Ball: return "ball";
    case JointSpec::Kind::Fixed: return "fixed";
  }
  return "rigid";
}

BodyState BodyState::attached(const Pose& relative) const {
  BodyState out;
  out.pose = pose * relative;
  const Vec3 r = out.pose.position - pose.position;
  out.angular_velocity = angular_velocity;
  out.angular_acceleration = angular_acceleration;
  out.linear_velocity = linear_velocity + angular_velocity.cross(r);
  out.linear_acceleration =
      linear_acceleration + angular_acceleration.cross(r) + angular_velocity.cross(angular_velocity.cross(r));
  return out;
}

// --- PhysicNode: reads the snapshot, writes its artifact's command buffer -------------------------

bool PhysicNode::isStatic() const noexcept { return world_->nodes[index_].is_static; }
int PhysicNode::bodyIndex() const noexcept { return world_->nodes[index_].body; }
const Pose& PhysicNode::poseInBody() const noexcept { return world_->nodes[index_].pose_in_body; }

BodyState PhysicNode::state() const {
  const detail::NodeData& n = world_->nodes[index_];
  if (n.body >= 0 && world_->started()) {
    const BodyState& body = world_->states[static_cast<std::size_t>(n.body)];
    return n.at_body ? body : body.attached(n.pose_in_body);
  }
  const detail::NodeSetup& setup = world_->node_setup[index_];
  BodyState s;
  s.pose = setup.pose;
  if (!n.is_static) {
    s.linear_velocity = setup.initial_linear;
    s.angular_velocity = setup.initial_angular;
  }
  return s;
}

Pose PhysicNode::pose() const { return world_->nodePose(index_); }

void PhysicNode::requireWritable() const {
  if (!detail::PhaseGuard::now.in_phase || detail::PhaseGuard::now.writer == artifact_) return;
  const Artifact* w = detail::PhaseGuard::now.writer;
  std::string who = w != nullptr ? std::string(detail::PhaseGuard::now.role) + " of artifact '" + w->name() + "'"
                                 : std::string("a ") + detail::PhaseGuard::now.role;
  throw Error(who + " tried to write to artifact '" + artifact_->name() +
              "': during a step, only an artifact's own driver writes its forces and torques");
}

void PhysicNode::addForce(const Vec3& force, Frame force_frame, const Vec3& point, Frame point_frame) {
  requireWritable();
  const detail::NodeData& n = world_->nodes[index_];
  if (n.body < 0 || !world_->started())
    throw Error("artifact '" + artifact_->name() + "', node '" + name() +
                "': forces apply to dynamic nodes once the environment has started");
  if (!force.allFinite() || !point.allFinite())
    throw Error("artifact '" + artifact_->name() + "', node '" + name() + "': force or point is NaN or infinite");
  const auto body = static_cast<std::size_t>(n.body);
  const BodyState& b = world_->states[body];
  const Pose node = n.at_body ? b.pose : b.pose * n.pose_in_body;
  const Vec3 f = force_frame == Frame::World ? force : Vec3(node.orientation * force);
  const Vec3 p = point_frame == Frame::Local ? node.transformPoint(point) : point;
  Wrench& w = world_->wrenches[body];
  w.force += f;
  w.torque += (p - b.pose.position).cross(f);
}

void PhysicNode::addTorque(const Vec3& torque, Frame frame) {
  requireWritable();
  const detail::NodeData& n = world_->nodes[index_];
  if (n.body < 0 || !world_->started())
    throw Error("artifact '" + artifact_->name() + "', node '" + name() +
                "': torques apply to dynamic nodes once the environment has started");
  if (!torque.allFinite())
    throw Error("artifact '" + artifact_->name() + "', node '" + name() + "': torque is NaN or infinite");
  const Pose node = pose();
  world_->wrenches[static_cast<std::size_t>(n.body)].torque +=
      frame == Frame::World ? torque : Vec3(node.orientation * torque);
}

void PhysicNode::setVelocity(const Vec3& linear, const Vec3& angular) {
  Environment& env = world_->env;
  if (detail::PhaseGuard::now.in_phase) throw Error("setVelocity is not allowed during a step");
  const PhysicsSettings& ps = env.settings().physics;
  if (!linear.allFinite() || !angular.allFinite() || linear.norm() > ps.max_linear_speed ||
      angular.norm() > ps.max_angular_speed)
    throw Error("artifact '" + artifact_->name() + "', node '" + name() +
                "': velocity must be finite and within max_linear_speed / max_angular_speed");
  detail::NodeData& n = world_->nodes[index_];
  if (env.state() == Environment::State::Setup) {
    world_->node_setup[index_].initial_linear = linear;
    world_->node_setup[index_].initial_angular = angular;
    world_->node_setup[index_].velocity_set = true;
    return;
  }
  if (n.is_static) throw Error("node '" + name() + "' of artifact '" + artifact_->name() + "' is static");
  if (env.state() != Environment::State::Running) throw Error("setVelocity: the environment is not running");
  BodyState b = world_->states[static_cast<std::size_t>(n.body)];
  const Vec3 r = b.pose.position - pose().position;  // node origin to centre of mass
  b.linear_velocity = linear + angular.cross(r);
  b.angular_velocity = angular;
  env.setBodyState(n.body, b);
}

}  // namespace ssx
