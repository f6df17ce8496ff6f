#pragma once
// The Bullet backend of PhysicEngine (Debian's libbullet, double precision). Private: nothing of
// Bullet leaves libssx.
//
// Bullet's pieces, ssx's order. Bodies are btRigidBody (principal axes as Bullet needs them),
// contacts come from Bullet's narrowphase (btCollisionDispatcher's algorithms: box-box, GJK/EPA,
// convex-plane with perturbation) and are solved by Bullet's sequential-impulse solver, one
// solveGroup per contact island. What btDiscreteDynamicsWorld would add is left out on purpose:
// its broadphase and pair cache, its persistent manifolds and its island sort carry an order
// from step to step that depends on history (an unstable quick-sort over a pair cache whose
// contents lag the bodies), so that neither a restored state nor another thread count would give
// the same bits. Instead, every substep:
//   1. the held wrenches and gravity go into each body's force accumulator;
//   2. each geom is posed from its body; ssx's grid broadphase finds the pairs within the contact
//      breaking threshold, in an order fixed by the state; each pair (and each geom near a plane)
//      gets a fresh manifold from Bullet's algorithm for its two shapes;
//   3. bodies joined by contacts or joints form islands (lowest body first, manifolds in pair order), each
//      solved by one solveGroup call; bodies in no contact go through the solver in batches
//      (there Bullet applies forces, torques and the implicit gyroscopic term);
//   4. Bullet integrates each body's transform.
// Islands, batches and narrowphase chunks are independent, so they run on the worker pool and the
// results do not depend on the thread count. Contacts are found afresh each substep (no warm
// start from the last one), so a body's transform and velocities are the whole state. Joints are
// Bullet's constraints (hinge, slider, point-to-point, fixed), their frames fixed in the bodies
// when made; they keep nothing from step to step that the solver uses (no warm start either). A
// joint made between steps is saved with its frames and made again from them on restore.

#include "engines/contact_groups.hpp"
#include "engines/contact_log.hpp"
#include "engines/grid_broadphase.hpp"

#include <ssx/physic_engine.hpp>

#include <memory>
#include <mutex>
#include <vector>

template <typename T>
class btAlignedObjectArray;
class btCollisionAlgorithm;
class btCollisionObject;
class btCollisionShape;
class btCompoundShape;
class btRigidBody;
class btPersistentManifold;
class btTypedConstraint;

namespace ssx::detail {

class BulletEngine final : public PhysicEngine {
 public:
  explicit BulletEngine(const PhysicsSettings& settings);
  ~BulletEngine() override;

  std::string name() const override { return "bullet"; }
  int addBody(const MassProperties& mass, const std::vector<Shape>& shapes, const BodyState& state) override;
  void setKinematic(int body) override;
  bool isKinematic(int body) const override;
  void setEnabled(int body, bool enabled) override;
  void setMassScale(int body, double mass_factor, double inertia_factor) override;
  int addStatic(const std::vector<Shape>& shapes, const Pose& pose) override;
  void setTaskRunner(TaskRunner* runner) override { runner_ = runner; }
  void step(Nanoseconds dt, std::span<const Wrench> wrenches) override;
  void readStates(std::span<BodyState> out) const override;
  void setState(int body, const BodyState& state) override;
  std::size_t bodyCount() const override { return bodies_.size(); }
  std::size_t contactCount() const override { return contact_count_; }
  void recordContacts(bool on) override { contact_log_.setOn(on); }
  const std::vector<EngineContact>& contacts() const override { return contact_log_.pairs(); }
  void saveState(StateWriter& out) const override;
  void restoreState(StateReader& in) override;
  int addJoint(const EngineJoint& joint) override;
  void setJointMotor(int joint, double velocity, double max_effort) override;
  void removeJoint(int joint) override;
  std::size_t jointCount() const override { return live_joints_; }
  void prepareRayQueries() override;
  void castRays(std::span<const Ray> rays, std::span<RayHit> hits, int ignore_begin, int ignore_end) const override;

 private:
  struct Geom {
    std::unique_ptr<btCollisionShape> shape;
    double offset[7];  // position and quaternion (x, y, z, w) in Bullet's body frame
    double diameter;
  };
  struct Body;
  struct StaticObject;
  struct Context;  // a narrowphase dispatcher and a solver, used by one task at a time
  struct Chunk {
    std::vector<std::pair<int, int>> pairs;
    std::vector<std::pair<btCollisionAlgorithm*, Context*>> algorithms;  // this substep's, and who made them
    std::vector<btPersistentManifold*> manifolds;                        // theirs with contacts
    std::shared_ptr<btAlignedObjectArray<btPersistentManifold*>> found;  // an algorithm's manifolds, reused
  };
  struct Island {
    int root;  // its lowest body
    std::size_t first_body, bodies, first_manifold, manifolds, first_joint, joints;
  };
  struct Joint {
    EngineJoint spec;
    std::unique_ptr<btTypedConstraint> constraint;
    double velocity = 0.0;    // the motor's target
    double max_effort = 0.0;  // off: 0
    // the joint's frame in the child's and the parent's Bullet body frame, as taken when it was
    // made (rotation row by row, then the origin): what makes it again to the bit
    double in_child[12] = {}, in_parent[12] = {};
    bool removed = false;  // a run-time joint let go of (its slot reusable)
  };

  class Lease;  // a context for one task, given back when the task ends
  template <class F>
  void forEach(std::size_t n, F&& task);
  void indexGeoms();
  void placeGeoms(std::size_t begin, std::size_t end);
  void collide(double h);
  void narrowphase(Context& context, Chunk& chunk, int a, int b, double h);
  void releaseContacts();
  // adds this substep's contact points, with the impulses the solver applied, to contact_log_
  void logContacts();
  void buildIslands();
  void solve(double h);
  void setMotors(double h);
  // makes the joint's Bullet constraint from its frames
  void makeConstraint(Joint& joint);
  void saveJoints(StateWriter& out) const;
  // reads the run-time joints of a saved state (checked; nothing changed yet)
  std::vector<Joint> loadJoints(StateReader& in) const;
  void seal() {
    if (!sealed_) scene_joints_ = joints_.size();
    sealed_ = true;
  }

  PhysicsSettings settings_;
  TaskRunner* runner_ = nullptr;
  std::vector<std::unique_ptr<Body>> bodies_;
  std::vector<std::unique_ptr<StaticObject>> statics_;
  std::vector<Joint> joints_;
  std::vector<int> articulation_;  // per body: the lowest body it is joined to (itself when none)
  std::vector<int> hangs_from_;    // per body: the static group its articulation hangs from, or -1
  bool labels_stale_ = false;      // joints came or went since articulation_ was computed
  int static_groups_ = 0;          // addStatic's calls so far
  std::size_t scene_joints_ = 0;   // joints_[0, scene_joints_) are the scene's (once sealed_)
  bool sealed_ = false;
  std::size_t live_joints_ = 0;
  std::vector<std::pair<int, std::size_t>> joint_order_;  // (island root, joint)
  std::vector<btTypedConstraint*> island_joints_;
  std::mutex contexts_mutex_;
  std::vector<std::unique_ptr<Context>> contexts_;
  std::vector<Context*> free_contexts_;
  // the grid's boxes: the bodies' geoms in body order, then the static shapes but planes
  struct Proxy {
    btCollisionObject* object;
    const btCollisionShape* shape;
    int body;  // -1: static
    int part;  // geom index within its body or static object
    int static_index;
  };
  std::vector<Proxy> proxies_;
  std::vector<GridBroadphase::Box> boxes_;
  struct ProxyPose;  // a btTransform, posed each substep
  std::vector<ProxyPose> poses_;
  std::vector<std::uint32_t> first_proxy_;
  std::size_t dynamic_proxies_ = 0;
  std::vector<int> planes_;  // indices into statics_
  bool proxies_stale_ = true;
  double cell_ = 1.0;
  GridBroadphase grid_;
  std::vector<Chunk> chunks_;
  std::vector<btPersistentManifold*> manifolds_;  // this substep's with contacts, in pair order
  ContactGroups groups_;  // bodies in contact this substep (joined ones too), grouped into islands
  std::vector<std::pair<int, int>> members_;                // (island root, body)
  std::vector<std::pair<int, std::size_t>> manifold_order_;  // (island root, manifold)
  std::vector<btCollisionObject*> island_bodies_;
  std::vector<btPersistentManifold*> island_manifolds_;
  std::vector<Island> islands_;
  std::vector<btCollisionObject*> free_bodies_;
  std::size_t contact_count_ = 0;
  detail::ContactLog contact_log_;  // recordContacts
};

}  // namespace ssx::detail
