#pragma once
// The ODE backend of PhysicEngine. Private: nothing of ODE leaves libssx.
//
// Parallel and deterministic: the bodies are spread over `partitions` ODE worlds, stepped at the
// same time on the environment's worker pool. One collision space holds every geom, so contacts
// are found as in one world; before the solver runs, bodies that touch are moved into one world
// (the home world of the lowest-numbered body of their contact group), and back home once they
// no longer touch. A body's home world follows from its index alone (blocks of kBlock bodies,
// dealt round the worlds), so which world steps which body never depends on the thread count.
// A free body's step does not depend on its world at all; a contact group is solved in one world
// as ODE would solve it anywhere, with that world's own copy of ODE's random seed.
//
// The geoms are not attached to ODE bodies: ODE's step would mark them moved in a shared space
// from every world's thread at once. They are posed from their body before each collision pass,
// with ODE's own arithmetic for a geom offset from its body, so contacts are what they would be.
// They are in no ODE space at all: posing them, finding the pairs (GridBroadphase, linear in the
// bodies however they are laid out, where ODE's sweep-and-prune is quadratic in a grid) and the
// contacts (dCollide) run in parallel chunks too.
//
// A body that no contact and no joint holds in a substep is not handed to ODE's world step at
// all: ssx steps it with QuickStep's own arithmetic for such a body (ode_free_bodies.cpp), which
// gives the same bits without the fixed cost of ODE's step per world (its memory arena, islands and
// threading stages, more than the arithmetic for a world of a few bodies). A world whose bodies are
// all free is not stepped by ODE; in one that has contacts or joints, the free bodies are disabled
// around dWorldQuickStep, which leaves the other islands as they would be. OdeSettings::
// integrate_free_bodies = false hands every body to ODE (the cross-check of the tests).
//
// Joined bodies (addJoint) are pinned: an articulation (the bodies joints join, directly or
// through others) always lies in one world, its home the home of its lowest body, so that the
// robots of a swarm of articulated robots step in parallel as free bodies do. An ODE joint belongs
// to one world and keeps frames (anchors, axes, the hinge's reference rotation) taken when it was
// made: when a contact group takes an articulation into another world, or it goes back home, its
// joints are made again there with their bodies put back where they were when each was first made,
// so that ODE computes the same frames to the bit (restoring a state does the same). The scene's
// joints are made in world 0, and each articulation goes home at the first step. A joint made
// between steps (a gripper closing) joins the two articulations in the world of the lower one;
// once the last joint holding a body is removed it goes back to its home world at the next step,
// as a body leaving a contact group does. Run-time joints, with their bodies' states when made,
// are part of the saved state.

#include "engines/contact_groups.hpp"
#include "engines/contact_log.hpp"
#include "engines/grid_broadphase.hpp"

#include <ssx/physic_engine.hpp>

#include <ode/ode.h>

#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

namespace ssx::detail {

// the arrays ODE's mesh geoms read while they live, one set per mesh (ode_meshes.cpp): outlives
// the geoms made with it
class OdeMeshes {
 public:
  OdeMeshes() = default;
  OdeMeshes(const OdeMeshes&) = delete;
  OdeMeshes& operator=(const OdeMeshes&) = delete;
  ~OdeMeshes();
  // a geom in no space for a mesh shape: its triangles when static, else its convex hull, given
  // about the hull's centre (ODE's convex collider wants the origin inside the hull; a link's mesh
  // often lies beside its frame): `centre` is where the geom's origin sits in the shape's frame
  dGeomID create(const Shape& shape, bool is_static, Vec3& centre);

 private:
  struct Hull {
    std::shared_ptr<const TriangleMesh> mesh;
    std::vector<dReal> planes;       // a, b, c, d per face: a x + b y + c z = d, normal outward
    std::vector<unsigned> polygons;  // 3, i, j, k per face
    std::vector<dReal> points;       // the hull's corners about `centre`
    Vec3 centre = Vec3::Zero();      // the mean of its corners, in the mesh's frame
  };
  struct Triangles {
    std::shared_ptr<const TriangleMesh> mesh;
    std::vector<dTriIndex> indices;
    dTriMeshDataID data = nullptr;
  };
  std::map<const TriangleMesh*, Hull> hulls_;
  std::map<const TriangleMesh*, Triangles> triangles_;
};

class OdeEngine final : public PhysicEngine {
 public:
  explicit OdeEngine(const PhysicsSettings& settings);
  ~OdeEngine() override;

  std::string name() const override { return "ode"; }
  int addBody(const MassProperties& mass, const std::vector<Shape>& shapes, const BodyState& state) override;
  void setKinematic(int body) override;
  bool isKinematic(int body) const override;
  void setEnabled(int body, bool enabled) override;
  void setMassScale(int body, double mass_factor, double inertia_factor) override;
  int addStatic(const std::vector<Shape>& shapes, const Pose& pose) override;
  void hotMemory(std::vector<MemoryRange>& out) const override;
  void setTaskRunner(TaskRunner* runner) override { runner_ = runner; }
  void step(Nanoseconds dt, std::span<const Wrench> wrenches) override;
  void readStates(std::span<BodyState> out) const override;
  void setState(int body, const BodyState& state) override;
  std::size_t bodyCount() const override { return bodies_.size(); }
  void saveState(StateWriter& out) const override;
  void restoreState(StateReader& in) override;
  std::size_t contactCount() const override { return contact_count_; }
  void recordContacts(bool on) override { contact_log_.setOn(on); }
  const std::vector<EngineContact>& contacts() const override { return contact_log_.pairs(); }
  int addJoint(const EngineJoint& joint) override;
  void setJointMotor(int joint, double velocity, double max_effort) override;
  void removeJoint(int joint) override;
  std::size_t jointCount() const override { return live_joints_; }
  void prepareRayQueries() override;
  void castRays(std::span<const Ray> rays, std::span<RayHit> hits, int ignore_begin, int ignore_end) const override;

  static constexpr int kBlock = 64;  // consecutive bodies that share a home world

 private:
  struct Partition {
    dWorldID world = nullptr;
    dJointGroupID contacts = nullptr;
    dThreadingImplementationID threading = nullptr;
    unsigned long rand_seed = 0;  // this world's own copy of ODE's process-wide dRand seed
    std::vector<int> order;       // its bodies in creation order (ODE lists them newest first)
    bool has_joints = false;      // joints in this substep (contacts, or an articulation's)
  };
  struct Geom {
    dGeomID id;
    dVector3 offset_position;  // in the body frame
    dMatrix3 offset_rotation;
    double diameter;  // of a sphere around it: its box is never longer, however it turns
  };
  struct Body {
    dBodyID id = nullptr;
    int partition = 0;
    int home = 0;
    bool kinematic = false;  // moved only by setState (dBodySetKinematic)
    bool pinned = false;     // joined to another body or the world: in its articulation's world
    bool listed = false;     // in away_
    bool enabled = true;     // in the world (setEnabled): else ODE's body is disabled, its boxes off
    dMass mass;   // now (setMassScale)
    dMass added;  // as addBody gave it
    // what stepping it free takes: its inverse inertia and mass as ODE computed them (kinematic:
    // zero), ODE's gyroscopic flag, and whether it has none of the options dxStepBody would apply
    dReal inv_inertia[12] = {};
    dReal inv_mass = 0;
    bool gyroscopic = true;
    bool plain = false;
    bool constrained = false;  // in a contact or held by a joint this substep
    std::vector<Geom> geoms;
  };

  struct Joint {
    EngineJoint spec;
    dJointID id = nullptr;
    std::vector<dReal> child_bits, parent_bits;  // the bodies' states when it was first made
    double velocity = 0.0, max_effort = 0.0;     // the motor (off: 0 effort)
    bool removed = false;                        // a run-time joint let go of (its slot reusable)
  };

  // makes partition p's ODE world, with the settings, unless it has one
  void openWorld(Partition& p);
  // makes joint j's ODE joint in its child's world from the bodies' current states
  void createJoint(Joint& joint);
  // makes joints_[k] for each k again (in slot order), its bodies put back where they were when
  // it was first made, then every body they hold back where it is now
  void remakeJoints(std::span<const int> joints);
  // moves articulation `root` (articulation_) into world `to`, its joints made again there
  void relocate(int root, int to);
  // labels, members and homes from the joints in place; with `list_away`, the bodies away from
  // home into away_
  void refreshLabels(bool list_away);
  void listAway(int body);
  std::span<const int> membersOf(int root) const {
    const auto r = static_cast<std::size_t>(root);
    return {members_.data() + member_offset_[r], members_.data() + member_offset_[r + 1]};
  }
  std::span<const int> jointsOf(int root) const {
    const auto r = static_cast<std::size_t>(root);
    return {art_joints_.data() + joint_offset_[r], art_joints_.data() + joint_offset_[r + 1]};
  }
  void applyMotor(const Joint& joint);
  // the joints made so far are the scene's (at the first step or restore)
  void seal() {
    if (!sealed_) scene_joints_ = joints_.size();
    sealed_ = true;
  }
  // pins the bodies some joint holds and lets the others go home (refreshLabels)
  void repin(bool list_away);
  void saveJoints(StateWriter& out) const;
  // reads the run-time joints of a saved state (checked; nothing changed yet)
  std::vector<Joint> loadJoints(StateReader& in) const;
  // throws StateError unless each joint's two bodies are in one world (`where`: per body)
  void checkJointWorlds(const std::vector<Joint>& run_time, const std::vector<int>& where) const;
  // the root of a contact group from two roots: a pinned one first, else the lower
  int firstOf(int a, int b) const {
    const bool pa = bodies_[static_cast<std::size_t>(a)].pinned, pb = bodies_[static_cast<std::size_t>(b)].pinned;
    return pa != pb ? (pa ? a : b) : std::min(a, b);
  }
  // appends the contacts between two geoms, with the surface settings
  void collidePair(dGeomID a, dGeomID b, std::vector<dContact>& out, std::vector<dContact>& scratch) const;
  void collide();
  void indexGeoms();
  // runs task(i) for i in [0, n) on the pool when the world is large enough, else here
  template <class F>
  void forEach(std::size_t n, F&& task);
  int homeOf(int body) const { return (body / kBlock) % static_cast<int>(partitions_.size()); }
  // recreates body i in partition p, bit for bit, last in its creation order
  void moveBody(int body, int partition);
  void groupContacts();
  // adds this substep's contacts, with the impulses the feedback measured, to contact_log_
  void logContacts(double h);
  void placeGeoms(std::size_t begin, std::size_t end);
  // whether a box lies wholly in front of a plane (n x = d: n, then d), clear of it
  static bool aboveOf(const GridBroadphase::Box& box, const std::array<double, 4>& plane);
  void stepPartition(Partition& p, double h, std::span<const Wrench> wrenches);
  // the constants stepping body i free needs, from its ODE body (after a change of its mass, its
  // kinematic flag or its ODE body)
  void cacheFreeStep(Body& body);
  bool isFree(const Body& body) const { return integrate_free_ && body.plain && !body.constrained; }
  // steps the free bodies of partition p (stepFreeOdeBody), in its order
  void stepFree(Partition& p, double h);
  // dWorldStep or dWorldQuickStep of partition p's world, with its own random seed when it has joints
  void solveWithOde(Partition& p, double h);

  PhysicsSettings settings_;
  dReal gravity_[3] = {0, 0, 0};  // as ODE's worlds hold it
  bool integrate_free_ = true;    // QuickStep and settings_.ode.integrate_free_bodies
  TaskRunner* runner_ = nullptr;
  std::vector<Partition> partitions_;
  // the partitions any body has been in, [0, used_partitions_): the others are never stepped (a
  // world of a few bodies touches one partition a step, not all of them)
  std::size_t used_partitions_ = 1;
  std::vector<Body> bodies_;
  std::vector<Joint> joints_;
  std::vector<int> articulation_;  // per body: the lowest body it is joined to (itself when none)
  std::vector<int> hangs_from_;    // per body: the static group its articulation hangs from, or -1
  // per articulation root: its bodies, ascending, and its joints in place, in slot order, at
  // members_[member_offset_[r], member_offset_[r + 1]) and likewise in art_joints_
  std::vector<int> members_, member_offset_, art_joints_, joint_offset_;
  bool labels_stale_ = false;      // joints came or went since articulation_ was computed
  std::size_t scene_joints_ = 0;   // joints_[0, scene_joints_) are the scene's (once sealed_)
  bool sealed_ = false;
  std::size_t live_joints_ = 0;
  std::size_t contacts_per_pair_ = 8;
  std::vector<dContact> contacts_;  // found in this substep, in a fixed order
  std::vector<dJointFeedback> feedback_;  // per contact of this substep, while recording contacts
  // the grid broadphase: one box per geom (the bodies' geoms in body order, then static ones),
  // the planes apart; contacts found per chunk, joined in chunk order
  std::vector<dGeomID> static_geoms_;
  int static_groups_ = 0;  // addStatic's calls so far
  OdeMeshes meshes_;       // the arrays the mesh geoms read (destroyed after them)
  std::vector<dGeomID> planes_;
  std::vector<std::array<double, 4>> planes_params_;  // each plane's n x = d: n, then d
  std::vector<dGeomID> proxy_geoms_;
  std::vector<GridBroadphase::Box> boxes_;
  std::vector<std::uint32_t> first_proxy_;  // per body
  std::size_t dynamic_proxies_ = 0;
  bool proxies_stale_ = true;
  double cell_ = 1.0;  // the grid's: twice the median geom diameter (fixed by the scene)
  GridBroadphase grid_;
  struct Chunk {
    std::vector<std::pair<int, int>> pairs;
    std::vector<dContact> contacts;
    std::vector<dContact> scratch;
  };
  std::vector<Chunk> chunks_;
  ContactGroups groups_;            // bodies in body-body contact this substep, grouped
  std::vector<int> away_;           // bodies not in their home world
  std::size_t contact_count_ = 0;
  detail::ContactLog contact_log_;  // recordContacts
  // ray geoms for castRays, one per query running at once
  mutable std::mutex rays_mutex_;
  mutable std::vector<dGeomID> free_rays_;
};

// an ODE geom in no space for a shape that is not a plane (ode_engine.cpp); a mesh's arrays are
// kept in `meshes`
// `centre`: where the geom's origin lies in the shape's frame (zero but for a hull, see OdeMeshes)
dGeomID createOdeGeom(const Shape& shape, OdeMeshes& meshes, bool is_static, Vec3& centre);

// ODE's process-wide initialisation, reference-counted (ode_engine.cpp): each acquireOde is
// matched by one releaseOde
void acquireOde();
void releaseOde();

// every thread that calls into ODE needs its own collision data (ode_engine.cpp)
void ensureThreadData();

// Free bodies (ode_free_bodies.cpp). Whether dxStepBody would do no more for body b than its
// plain step (enabled, no damping, no finite rotation, no angular speed cap, gravity on):
bool odeBodyIsPlain(dBodyID b);
// a body's inverse inertia (12 values, ODE's 3x4 layout) and inverse mass as dBodySetMass and
// dBodySetKinematic leave them
void odeInverseInertia(const dMass& mass, bool kinematic, dReal* inv_inertia, dReal& inv_mass);
// one QuickStep substep of h seconds of a body that no constraint holds, its accumulators holding
// the applied force and torque: the same bits as dWorldQuickStep's, the accumulators cleared after
void stepFreeOdeBody(dBodyID b, const dMass& mass, const dReal* inv_inertia, dReal inv_mass, bool gyroscopic,
                     const dReal* gravity, dReal h);

// a body's state bit for bit (ode_engine.cpp): kOdeBodyReals values
inline constexpr std::size_t kOdeBodyReals = 3 + 4 + 12 + 3 + 3;
void readOdeBits(dBodyID b, dReal* out);
void writeOdeBits(dBodyID b, const dReal* in);

template <class F>
void OdeEngine::forEach(std::size_t n, F&& task) {
  constexpr std::size_t kParallelFrom = 2 * kBlock;  // bodies
  if (runner_ == nullptr || runner_->threads() < 2 || bodies_.size() < kParallelFrom || n < 2) {
    for (std::size_t i = 0; i < n; ++i) task(i);
    return;
  }
  runner_->forEach(
      n,
      [](void* context, std::size_t i) {
        ensureThreadData();
        (*static_cast<F*>(context))(i);
      },
      &task);
}

}  // namespace ssx::detail
