#pragma once
/// @file
/// Physic node trees: what a body is made of (shapes, mass, inertia), and the live nodes that
/// read the simulated state and take forces.

#include <ssx/error.hpp>
#include <ssx/export.hpp>
#include <ssx/types.hpp>

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ssx {

class Artifact;
namespace detail {
struct World;
}

/// A triangle mesh read from a file (STL, OBJ, COLLADA and whatever else assimp reads), scaled
/// as its description asks, in the frame of the shape that holds it, with its convex hull (computed
/// once when the mesh is read). A moving body collides and weighs as the hull; a static one
/// collides with the triangles themselves.
struct SSX_EXPORT TriangleMesh {
  std::string file;                 ///< where it was read from (messages)
  Vec3 scale = Vec3::Ones();        ///< the scale the file's coordinates were multiplied by
  std::vector<Vec3> vertices;       ///< m
  std::vector<std::uint32_t> triangles;  ///< three vertex indices per triangle, counter-clockwise seen from outside
  std::vector<Vec3> hull_vertices;       ///< the convex hull's corners, m
  std::vector<std::uint32_t> hull_triangles;  ///< its faces, three indices into hull_vertices each, outward
  double hull_volume = 0.0;                   ///< m^3
  Vec3 hull_centroid = Vec3::Zero();          ///< the hull's centre of volume
  /// The hull's inertia per kilogram about its centroid, mesh axes (uniform density), m^2.
  Mat3 hull_unit_inertia = Mat3::Zero();
  Vec3 min = Vec3::Zero();  ///< the vertices' bounding box: its lowest corner, m
  Vec3 max = Vec3::Zero();  ///< the vertices' bounding box: its highest corner, m

  /// Fills in the hull (and the bounding box) from the vertices: Bullet's btConvexHullComputer.
  /// Throws Error when they span no volume (fewer than four points off one plane).
  void computeHull();
};

/// A collision and mass shape, posed relative to the node that holds it. Cylinders and capsules
/// lie along their local z axis. A plane is the half-space below its local xy-plane (normal +z)
/// and is allowed only on static nodes.
struct SSX_EXPORT Shape {
  /// The shape's geometry.
  enum class Kind : std::uint8_t { Box, Sphere, Cylinder, Capsule, Plane, Mesh };
  Kind kind = Kind::Box;     ///< which geometry; the fields below that it uses
  Vec3 size = Vec3::Ones();  ///< box: full edge lengths, m
  double radius = 0.5;       ///< sphere, cylinder, capsule: m
  double length = 1.0;       ///< cylinder: full height; capsule: length of the cylindrical part, m
  Pose pose;                 ///< relative to the node
  double density = 1000.0;   ///< kg/m^3; used when the node's mass comes from its shapes
  /// mesh: its triangles and hull (shared by every shape and artifact that uses the same file)
  std::shared_ptr<const TriangleMesh> mesh;

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
  /// A mesh: its convex hull on a moving body, its triangles on a static one.
  static Shape fromMesh(std::shared_ptr<const TriangleMesh> mesh, const Pose& pose = {});

  /// Volume in m^3 (0 for a plane).
  double volume() const;
  /// Inertia about the shape's own centre, in its own axes, for a given mass.
  Mat3 unitInertia(double mass) const;
  /// The shape's centre of volume in its own frame (the origin but for a mesh: its hull's centroid).
  Vec3 centroid() const;
};

/// The point of a shape's surface nearest to `p` (world frame), the shape posed at `world`; `p`
/// itself when it is inside. A plane: the foot of the perpendicular from `p`.
SSX_EXPORT Vec3 nearestSurfacePoint(const Shape& shape, const Pose& world, const Vec3& p);

/// How a child node is joined to its parent. `Rigid` (the default): the child is part of its
/// parent's rigid body. Any other kind makes the child (with its rigid descendants) a body of its
/// own, joined to its parent's body at the child's origin. The joint's position is 0 where the
/// tree was placed; a hinge turns about `axis` (positive: the child turns right-handed about it
/// relative to the parent), a slider moves the child along `axis`.
struct SSX_EXPORT JointSpec {
  /// The joint's degrees of freedom.
  enum class Kind : std::uint8_t {
    Rigid,   ///< no joint: the child is part of its parent's body
    Hinge,   ///< turns about `axis` (1 degree of freedom, rad)
    Slider,  ///< slides along `axis` (1 degree of freedom, m)
    Ball,    ///< turns freely about its origin (3 rotational degrees of freedom; no limits or motor)
    Fixed,   ///< a body of its own, held rigidly (its own contacts, and a joint that can be measured)
  };
  Kind kind = Kind::Rigid;    ///< which joint
  Vec3 axis = Vec3::UnitZ();  ///< hinge and slider: the axis in the child's frame (unit length)
  double lower = -std::numeric_limits<double>::infinity();  ///< hinge (rad, >= -pi) or slider (m) limit
  double upper = std::numeric_limits<double>::infinity();   ///< hinge (rad, <= pi) or slider (m) limit
  double damping = 0.0;  ///< viscous: N m s/rad (hinge) or N s/m (slider)
  /// The motor's largest torque (hinge, N m) or force (slider, N); 0: no motor. A driver sets its
  /// target velocity or position (PhysicNode::setJointVelocity, setJointPosition).
  double max_effort = 0.0;
  /// The fastest the motor turns or moves the joint (rad/s or m/s): commanded velocities, and the
  /// position servo's, are held within it. Infinite: no bound.
  double max_velocity = std::numeric_limits<double>::infinity();
  /// Coulomb friction in the joint (N m or N): while no motor command holds it, the joint is
  /// braked with at most this effort (0: none).
  double friction = 0.0;

  /// Whether the child is a body of its own (any kind but Rigid).
  bool isBody() const noexcept { return kind != Kind::Rigid; }
  /// Whether the joint has one degree of freedom with a position (hinge or slider).
  bool hasPosition() const noexcept { return kind == Kind::Hinge || kind == Kind::Slider; }
};

/// The name of a joint kind, as in a scene file: "rigid", "hinge", "slider", "ball", "fixed".
SSX_EXPORT const char* jointKindName(JointSpec::Kind kind);

/// One node of a physic node tree, as described in a file or in code (the constant model).
/// Children are posed relative to their parent; a child without a joint is rigidly part of its
/// parent's body, a child with one is a body of its own (see JointSpec).
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
  JointSpec joint;                     ///< children only: how it is joined to its parent
  SourceLocation where;                ///< where it was described, for messages
  std::vector<PhysicNodeSpec> children;  ///< nodes attached to this one

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
/// only on static roots, unique names, each body (the root and every joined child) with mass and
/// inertia, joints that make sense (a unit axis, limits in order and within [-pi, pi] for a hinge,
/// no limit or motor on a ball or fixed joint). Throws ConfigError naming the node.
SSX_EXPORT void validatePhysicTree(const PhysicNodeSpec& root);

/// Combined mass properties of a whole tree, every node as placed (joined children too), in the
/// root node's frame: the robot's total mass.
SSX_EXPORT MassProperties combinedMass(const PhysicNodeSpec& root);

/// Mass properties of the rigid body that `node` begins (a root, or a joined child): the node and
/// its descendants down to the next joined ones, in `node`'s frame.
SSX_EXPORT MassProperties bodyMass(const PhysicNodeSpec& node);

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
  /// moving at `linear`. Before start: the initial state (set on a root, of every body of its
  /// tree moving as one, but those set on their own). Between steps: applied at once.
  void setVelocity(const Vec3& linear, const Vec3& angular);

  /// The joint that joins this node to its parent (kind Rigid: none).
  const JointSpec& joint() const noexcept { return spec_->joint; }
  /// A hinge's angle (rad, in (-pi, pi]) or a slider's displacement (m) from where the tree was
  /// placed; 0 before start. Throws Error for a node without a hinge or slider.
  double jointPosition() const;
  /// A hinge's (rad/s) or slider's (m/s) rate: the child's motion relative to the parent about
  /// or along the axis. 0 before start.
  double jointVelocity() const;
  /// Drives the joint's motor toward a velocity (rad/s or m/s) with at most its `max_effort`;
  /// held until changed. Written like a force: by the artifact's own driver during a step, or by
  /// the program between steps. Throws Error when the joint has no motor.
  void setJointVelocity(double velocity);
  /// Drives the joint's motor toward a position (rad or m; within the limits): each step the motor
  /// is given the velocity that would reach it at the step's end, within `max_effort`.
  void setJointPosition(double position);

  /// Holds `other`'s body to this node's body by a fixed joint, as the two are when it is made (a
  /// gripper closing on an object, two robots docking): they then move as one and do not collide
  /// with each other. With `joint` JointSpec::Kind::Ball, by a ball joint at this node's origin
  /// instead (a hook, a tether's end): `other` keeps its distance from that point and turns freely
  /// about it. `other` may be static: this node's body is then held in place. Asked for by
  /// the artifact's own driver during a step, it is made as the drivers phase ends, at the poses
  /// the drivers saw (requests are carried out artifact by artifact, each artifact's in the order
  /// asked); by the program between steps, at once. A pair already joined this way stays as it is.
  /// Part of the saved state. Throws Error before start, for two nodes of one body, for a static
  /// node holding, for a ghost and for a joint other than fixed or ball.
  void attach(const PhysicNode& other, JointSpec::Kind joint = JointSpec::Kind::Fixed);
  /// Lets go of every body this node holds (its attach calls), as attach: as the drivers phase
  /// ends, or at once between steps.
  void release();
  /// Frees this node's body of every run-time joint on it, whoever made it (an object taken out of
  /// a gripper before the program moves it), as release.
  void detach();
  /// How many run-time joints (attach) hold this node's body or are held by it: a driver's
  /// request counts once its drivers phase has ended.
  std::size_t attachments() const noexcept;

 private:
  void requireWritable() const;

  detail::World* world_;
  Artifact* artifact_;
  const PhysicNodeSpec* spec_;
  PhysicNode* parent_;
  std::size_t index_;  // in the world's node table
};

}  // namespace ssx
