#pragma once
/// @file
/// Physic node trees: what a body is made of (shapes, mass, inertia), and the live nodes that
/// read the simulated state and take forces.

#include <ssx/error.hpp>
#include <ssx/export.hpp>
#include <ssx/types.hpp>

#include <optional>
#include <string>
#include <vector>

namespace ssx {

class Artifact;
namespace detail {
struct World;
}

/// A collision and mass shape, posed relative to the node that holds it. Cylinders and capsules
/// lie along their local z axis. A plane is the half-space below its local xy-plane (normal +z)
/// and is allowed only on static nodes.
struct SSX_EXPORT Shape {
  /// The shape's geometry.
  enum class Kind : std::uint8_t { Box, Sphere, Cylinder, Capsule, Plane };
  Kind kind = Kind::Box;     ///< which geometry; the fields below that it uses
  Vec3 size = Vec3::Ones();  ///< box: full edge lengths, m
  double radius = 0.5;       ///< sphere, cylinder, capsule: m
  double length = 1.0;       ///< cylinder: full height; capsule: length of the cylindrical part, m
  Pose pose;                 ///< relative to the node
  double density = 1000.0;   ///< kg/m^3; used when the node's mass comes from its shapes

  /// A box with full edge lengths `size`, m.
  static Shape box(const Vec3& size, const Pose& pose = {});
  /// A sphere, m.
  static Shape sphere(double radius, const Pose& pose = {});
  /// A cylinder along z, `length` its full height, m.
  static Shape cylinder(double radius, double length, const Pose& pose = {});
  /// A capsule along z, `length` the length of its cylindrical part, m.
  static Shape capsule(double radius, double length, const Pose& pose = {});
  /// A plane (static nodes only): the half-space below the posed xy-plane.
  static Shape plane(const Pose& pose = {});

  /// Volume in m^3 (0 for a plane).
  double volume() const;
  /// Inertia about the shape's own centre, in its own axes, for a given mass.
  Mat3 unitInertia(double mass) const;
};

/// The point of a shape's surface nearest to `p` (world frame), the shape posed at `world`; `p`
/// itself when it is inside. A plane: the foot of the perpendicular from `p`.
SSX_EXPORT Vec3 nearestSurfacePoint(const Shape& shape, const Pose& world, const Vec3& p);

/// One node of a physic node tree, as described in a file or in code (the constant model).
/// Children are rigidly attached to their parent (joints come later), posed relative to it.
///
/// Mass, in order of precedence: `mass` and `inertia` given: used as they are (inertia about
/// `center_of_mass`, node axes); `mass` only: shapes' inertia scaled to that mass; neither:
/// shapes' volume times density. A node without shapes and mass is a massless frame (a sensor
/// mount, say).
struct SSX_EXPORT PhysicNodeSpec {
  std::string name;  ///< unique within the artifact; plugins name nodes by it
  Pose pose;  ///< relative to the parent node; for a root, relative to the artifact's pose
  std::vector<Shape> shapes;  ///< its collision and mass shapes (none: a frame, or mass given)
  std::optional<double> mass;          ///< kg
  std::optional<Mat3> inertia;         ///< kg m^2, about the centre of mass, node axes; needs `mass`
  Vec3 center_of_mass = Vec3::Zero();  ///< node frame; used with an explicit `mass`
  bool is_static = false;              ///< root only: fixed in the world, never moves
  SourceLocation where;                ///< where it was described, for messages
  std::vector<PhysicNodeSpec> children;  ///< nodes rigidly attached to this one

  /// Appends a child and returns it.
  PhysicNodeSpec& addChild(PhysicNodeSpec child);
};

/// Mass properties of a rigid body: total mass, centre of mass and inertia about it.
struct MassProperties {
  double mass = 0.0;  ///< kg
  Vec3 center_of_mass = Vec3::Zero();  ///< in the frame the properties were computed in
  Mat3 inertia = Mat3::Zero();         ///< about the centre of mass, axes of that frame
};

/// Checks a node tree: positive mass, positive definite inertia, positive shape sizes, planes
/// only on static roots, unique names. Throws ConfigError naming the node.
SSX_EXPORT void validatePhysicTree(const PhysicNodeSpec& root);

/// Combined mass properties of a whole tree (children rigidly attached), in the root node's frame.
SSX_EXPORT MassProperties combinedMass(const PhysicNodeSpec& root);

/// A live node of an artifact's physic tree: reads its state from the environment's current
/// snapshot and takes forces and torques for its rigid body.
///
/// Reads are safe from any phase and thread (they read the read-only snapshot). Writes
/// (`addForce`, `addTorque`) go into the owning artifact's command buffer: during a step only
/// that artifact's own driver may write; outside a step, the embedding program may.
class SSX_EXPORT PhysicNode {
 public:
  /// Made by Artifact::addPhysicRoot (the world is the core's and cannot be named outside it).
  /// `index` is the node's place in the world's node table.
  PhysicNode(detail::World& world, Artifact& artifact, const PhysicNodeSpec& spec, PhysicNode* parent,
             std::size_t index)
      : world_(&world), artifact_(&artifact), spec_(&spec), parent_(parent), index_(index) {}
  PhysicNode(const PhysicNode&) = delete;
  PhysicNode& operator=(const PhysicNode&) = delete;

  /// The node's name (its spec's).
  const std::string& name() const noexcept { return spec_->name; }
  /// What the node was made from.
  const PhysicNodeSpec& spec() const noexcept { return *spec_; }
  /// The artifact the node belongs to.
  Artifact& artifact() noexcept { return *artifact_; }
  /// @copydoc artifact()
  const Artifact& artifact() const noexcept { return *artifact_; }
  /// The parent node, or nullptr for a root.
  const PhysicNode* parent() const noexcept { return parent_; }
  /// Fixed in the world (its root is static).
  bool isStatic() const noexcept;
  /// Index of this node among all nodes of the environment (artifact by artifact, trees in order).
  std::size_t nodeIndex() const noexcept { return index_; }
  /// Index of the rigid body this node belongs to (children share their root's body), or -1.
  int bodyIndex() const noexcept;
  /// This node's frame relative to its body's centre-of-mass frame.
  const Pose& poseInBody() const noexcept;

  /// Pose, velocities and accelerations of this node's frame origin, world frame.
  BodyState state() const;
  /// Pose of this node's frame, world frame (the position and orientation of state()).
  Pose pose() const;

  /// Adds a force at a point. `force` is in `force_frame`; `point` in `point_frame` (Local:
  /// this node's frame; the default, the node's origin). Held until the driver next runs.
  void addForce(const Vec3& force, Frame force_frame = Frame::World, const Vec3& point = Vec3::Zero(),
                Frame point_frame = Frame::Local);
  /// Adds a torque, in `frame`.
  void addTorque(const Vec3& torque, Frame frame = Frame::World);
  /// Sets the linear and angular velocity (world frame) of the node's body, the node's origin
  /// moving at `linear`. Before start: the initial state. Between steps: applied at once.
  void setVelocity(const Vec3& linear, const Vec3& angular);

 private:
  void requireWritable() const;

  detail::World* world_;
  Artifact* artifact_;
  const PhysicNodeSpec* spec_;
  PhysicNode* parent_;
  std::size_t index_;  // in the world's node table
};

}  // namespace ssx
