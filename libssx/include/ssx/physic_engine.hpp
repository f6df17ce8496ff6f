#pragma once
/// @file
/// The abstract physics engine. Nothing of a backend's library appears here, so another backend
/// can be added without touching clients.

#include <ssx/descriptor.hpp>
#include <ssx/export.hpp>
#include <ssx/physic_node.hpp>
#include <ssx/parameters.hpp>
#include <ssx/state.hpp>
#include <ssx/types.hpp>

#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace ssx {

/// Settings of the ODE engine (`<physics engine="ode">`).
struct OdeSettings {
  /// ODE's two solvers.
  enum class Solver : std::uint8_t {
    QuickStep,  ///< iterative (ODE's dWorldQuickStep): O(n) in constraints; the default
    Exact,      ///< direct LCP (ODE's dWorldStep): accurate, O(n^3) per island
  };
  Solver solver = Solver::QuickStep;  ///< QuickStep (default) or the exact LCP solver
  int iterations = 20;  ///< QuickStep iterations
  double sor = 1.3;     ///< QuickStep over-relaxation
  double erp = 0.2;     ///< error reduction parameter
  double cfm = 1e-9;    ///< constraint force mixing
  double contact_soft_cfm = 1e-6;  ///< constraint force mixing of contacts (softness)
  double contact_soft_erp = 0.2;   ///< error reduction of contacts
  double contact_surface_layer = 1e-3;  ///< m of allowed penetration, for resting stability
  int max_contacts = 8;                 ///< per pair of geoms
  /// Worlds the bodies are spread over, stepped in parallel on the worker pool (bodies in
  /// contact are moved into one). Results do not depend on it when no two bodies touch, and never
  /// on the thread count.
  int partitions = 16;
  /// Bodies that no contact and no joint holds in a step are stepped by ssx with QuickStep's own
  /// arithmetic for such a body (the same bits, without ODE's fixed cost per world and step);
  /// false hands every body to ODE's step (a cross-check; the results are the same).
  bool integrate_free_bodies = true;
};

/// Settings of the Bullet engine (`<physics engine="bullet">`): Bullet's sequential-impulse solver.
struct BulletSettings {
  int iterations = 10;                      ///< solver iterations per substep
  double erp = 0.2;                         ///< error reduction of contacts (Bullet's erp2)
  double cfm = 0.0;                         ///< constraint force mixing (Bullet's globalCfm)
  bool split_impulse = true;               ///< deep penetrations pushed out without adding momentum
  double split_impulse_threshold = -0.04;  ///< m, <= 0: shallower penetrations are pushed out through the velocity
  double linear_slop = 0.0;                 ///< m of penetration allowed at rest
};

/// Settings of the physics: what every engine takes, and each engine's own.
struct PhysicsSettings {
  using Solver = OdeSettings::Solver;  ///< ODE's solvers, under a shorter name
  std::string engine = "ode";  ///< one of physicEngineNames()
  Vec3 gravity{0.0, 0.0, -9.81};  ///< m/s^2, world frame
  int substeps = 1;     ///< equal physics steps per environment timestep
  // contacts
  double friction = 1.0;     ///< Coulomb coefficient
  double restitution = 0.0;  ///< bounce, 0..1
  // divergence guards: a body past these speeds stops the run (StepError) before the engine
  // meets a NaN; far beyond anything a robot does, far below where the arithmetic breaks
  double max_linear_speed = 1e5;   ///< m/s
  double max_angular_speed = 1e6;  ///< rad/s
  OdeSettings ode;        ///< used when engine == "ode"
  BulletSettings bullet;  ///< used when engine == "bullet"
  /// The engine's own settings, as its class declares them (PhysicEngineClass::settings), named
  /// for the engine they belong to (`Descriptor("mine").set("time_scale", 0.5)`; an empty name:
  /// whichever engine is chosen). The scene reader fills them in from `<physics>`;
  /// createPhysicEngine checks them and fills in the defaults (options named for another engine,
  /// after a switch, are not that engine's: it starts from its defaults). ODE and Bullet read
  /// theirs typed, from `ode` and `bullet`.
  Descriptor options;
};

/// Force and torque on a body, world frame, torque about the centre of mass.
struct Wrench {
  Vec3 force = Vec3::Zero();   ///< N, world frame
  Vec3 torque = Vec3::Zero();  ///< N m, world frame, about the centre of mass
};

/// A joint between two bodies of an engine, as PhysicEngine::addJoint takes it.
struct EngineJoint {
  JointSpec::Kind kind = JointSpec::Kind::Fixed;  ///< hinge, slider, ball or fixed (not Rigid)
  int parent = -1;  ///< a body, or -1: the static world
  int child = 0;    ///< a body
  /// When `parent` is -1: the static shapes the child hangs from (addStatic's group), or -1. The
  /// child's articulation never collides with them, as joined bodies never collide.
  int static_group = -1;
  /// The joint's frame in the world where the bodies are now (their initial states): its origin
  /// is the anchor, its z axis the hinge's or slider's axis. Position 0 is this configuration.
  Pose frame;
  double lower = -std::numeric_limits<double>::infinity();  ///< rad or m; infinite: no limit
  double upper = std::numeric_limits<double>::infinity();   ///< rad or m
  /// Made while the world runs (a gripper closing): removable, and part of the saved state. The
  /// scene's joints (false) all come first, before any step.
  bool run_time = false;
};

/// A segment to cast against the shapes (PhysicEngine::castRays).
struct Ray {
  Vec3 from = Vec3::Zero();  ///< m, world frame
  Vec3 to = Vec3::Zero();    ///< m, world frame
};

/// Where a ray first meets a shape.
struct RayHit {
  bool hit = false;                                          ///< whether it met any
  double distance = std::numeric_limits<double>::infinity();  ///< m from the ray's start
  Vec3 point = Vec3::Zero();                                 ///< world frame
  Vec3 normal = Vec3::Zero();                                ///< of the surface met, world frame
  int body = -1;                                             ///< the body met; -1: a static shape
};

/// A pair of bodies, or a body and the static world, that touched in the last step
/// (PhysicEngine::contacts).
struct EngineContact {
  int body_a = 0;                ///< a dynamic body
  int body_b = -1;               ///< the other, with a larger index; -1: a static shape
  Vec3 position = Vec3::Zero();  ///< m, world frame: the pair's deepest contact point
  Vec3 normal = Vec3::Zero();    ///< unit, world frame, at that point: from body_b towards body_a
  /// N s: the normal impulse the solver applied over the step (every substep), summed over the
  /// pair's contact points
  double impulse = 0.0;
  /// With body_b -1: the static shapes touched, as the group addStatic returned for them (a
  /// body touching two static roots makes two contacts); -1 otherwise
  int static_group = -1;
};

/// Runs independent tasks on the environment's worker pool, for an engine that can step parts
/// of its world in parallel.
class SSX_EXPORT TaskRunner {
 public:
  virtual ~TaskRunner();
  /// The threads tasks may run on (1: only the caller's).
  virtual unsigned threads() const = 0;
  /// Calls task(context, i) for every i in [0, n), on any of the pool's threads; returns when all
  /// are done. The first exception a task throws is rethrown here.
  virtual void forEach(std::size_t n, void (*task)(void* context, std::size_t i), void* context) = 0;
};

/// A block of memory: `bytes` from `address` (Environment::hotMemory).
struct MemoryRange {
  const void* address = nullptr;  ///< where it starts
  std::size_t bytes = 0;           ///< how long it is
};

/// An abstract rigid-body engine. Bodies are created with their centre of mass at the body
/// origin; the Environment flattens node trees into bodies. Called from one thread at a time
/// (the thread calling Environment::step), never from the parallel phases; it may use the
/// TaskRunner it is given inside its own calls.
class SSX_EXPORT PhysicEngine {
 public:
  virtual ~PhysicEngine();
  /// "ode" or "bullet".
  virtual std::string name() const = 0;

  /// The pool the engine may run its own parallel work on (null: everything on the caller's
  /// thread). Results must not depend on it.
  virtual void setTaskRunner(TaskRunner* runner) { (void)runner; }

  /// Adds a dynamic body; `state.pose` is the pose of its centre-of-mass frame. Returns its index.
  virtual int addBody(const MassProperties& mass, const std::vector<Shape>& shapes, const BodyState& state) = 0;
  /// Makes a body kinematic: from now on it moves only as setState puts it, at the velocities set
  /// with it, whatever forces, gravity and contacts act on it. Dynamic bodies that touch it meet an
  /// infinitely heavy body moving at its velocity; it does not collide with static shapes or with
  /// other kinematic bodies. Before the first step; which bodies are kinematic is part of the scene,
  /// not of the saved state.
  virtual void setKinematic(int body) = 0;
  /// Whether setKinematic made `body` kinematic.
  virtual bool isKinematic(int body) const = 0;
  /// Takes a body out of the world (false) or puts it back (true), between steps. A body out of
  /// the world keeps its state as it is (no force, gravity, joint or contact moves it), touches
  /// nothing and no ray meets it; a joint between two bodies out of the world holds nothing. Put
  /// back, it moves on from the state it has then (forces applied to it while it was out are
  /// dropped). Not part of the saved state: the Environment sets it again after restoreState.
  /// Default: throws Error (an engine that cannot take bodies out of its world).
  virtual void setEnabled(int body, bool enabled);
  /// Scales a dynamic body's mass and its inertia (about its centre of mass) by these factors,
  /// relative to what addBody gave it ((1, 1): as added), from the next step on; its state stays.
  /// Between steps; a kinematic body ignores it (it has no mass to move).
  virtual void setMassScale(int body, double mass_factor, double inertia_factor) = 0;
  /// Joins two bodies (or a body and the world) where they are now and returns the joint's index.
  /// Bodies joined, directly or through others, do not collide with each other and are always
  /// solved together. A scene joint is made before the first step (or restoreState); a run-time
  /// one (EngineJoint::run_time) between steps, part of the saved state until removeJoint: it
  /// takes the lowest index a removed run-time joint left, else the next. Throws Error for a scene
  /// joint after a run-time one or a step.
  virtual int addJoint(const EngineJoint& joint) = 0;
  /// Removes a run-time joint (between steps); its bodies move freely of each other from the next
  /// step. Throws Error for a joint of the scene or one already removed.
  virtual void removeJoint(int joint) = 0;
  /// Sets a joint's motor: a target velocity (rad/s or m/s of the child relative to the parent,
  /// about or along the frame's z axis), reached with at most `max_effort` (N m or N; 0: the motor
  /// is off and the joint turns freely); held until set again. Off until first set.
  virtual void setJointMotor(int joint, double velocity, double max_effort) = 0;
  /// How many joints there are (the scene's and the run-time ones not removed).
  virtual std::size_t jointCount() const = 0;
  /// Poses every shape where its body is now, for castRays (after a step, before the queries).
  virtual void prepareRayQueries() = 0;
  /// Casts each ray against every shape but those of bodies [ignore_begin, ignore_end), with the
  /// engine's own ray queries; hits[i] is the first shape rays[i] meets. Read only, so safe from
  /// several threads at once between prepareRayQueries and the next step.
  virtual void castRays(std::span<const Ray> rays, std::span<RayHit> hits, int ignore_begin, int ignore_end) const = 0;
  /// Adds shapes fixed in the world at `pose`; returns their group (0, 1, ... in the order of the
  /// calls), which a joint to the static world names in EngineJoint::static_group.
  virtual int addStatic(const std::vector<Shape>& shapes, const Pose& pose) = 0;
  /// Integrates one timestep (in the configured substeps), with `wrenches[i]` applied to body i
  /// throughout.
  virtual void step(Nanoseconds dt, std::span<const Wrench> wrenches) = 0;
  /// Writes every body's pose and velocities into `out` (size bodyCount()); accelerations are
  /// left as they are.
  virtual void readStates(std::span<BodyState> out) const = 0;
  /// Overwrites one body's pose and velocities.
  virtual void setState(int body, const BodyState& state) = 0;
  /// How many dynamic bodies were added.
  virtual std::size_t bodyCount() const = 0;
  /// Appends the memory the next step reads first (Environment::hotMemory). Default: nothing.
  virtual void hotMemory(std::vector<MemoryRange>& out) const { (void)out; }
  /// Contacts generated in the last step.
  virtual std::size_t contactCount() const = 0;
  /// Whether contacts() lists the contacts of each step from now on (off: nothing is kept, and
  /// nothing is spent on it); either way the list is emptied.
  virtual void recordContacts(bool on) = 0;
  /// The contacts of the last step while recordContacts is on, one per pair: ascending body_a,
  /// then body_b (the static world first). The same on any thread count.
  virtual const std::vector<EngineContact>& contacts() const = 0;
  /// Writes everything that determines the engine's next steps (body states bit for bit, its
  /// random seed), for Environment::saveState.
  virtual void saveState(StateWriter& out) const = 0;
  /// Reads it back into an engine built from the same scene; throws StateError (the engine is
  /// then unchanged) when the data does not fit it.
  virtual void restoreState(StateReader& in) = 0;
};

/// A change of physics engine while a run goes on (Environment::switchPhysics).
struct PhysicsSwitch {
  Nanoseconds time = 0;  ///< simulated time of the switch: the next step was the new engine's first
  std::string from;      ///< the engine that stepped until then
  std::string to;        ///< the engine that steps from then on
};

/// A physics engine as a scene chooses it (`<physics engine="NAME">`): what registerPhysicEngine
/// takes. An engine is a PhysicEngine implementation and one of these; ODE and Bullet are
/// registered so (`libssx/src/engines/{ode,bullet}/*_class.cpp`), and a program registers its own
/// before it loads a scene.
struct PhysicEngineClass {
  std::string name;  ///< what `engine="..."` says: lower-case letters, digits and '_'
  std::string doc;   ///< one line on what it is
  /// Its own settings: the attributes of `<physics>` besides the common ones (gravity, substeps,
  /// friction, restitution, max_linear_speed, max_angular_speed), declared as a plugin declares
  /// its parameters (ssx/parameters.hpp's param::). The scene reader checks them against these
  /// (and `ssx validate` with it); `ssx plugins --params NAME` prints them.
  std::vector<ssx_plugin_param> settings;
  /// Makes an engine of these settings (`settings.options` holds its own, checked, defaults filled in).
  std::function<std::unique_ptr<PhysicEngine>(const PhysicsSettings& settings)> create;
  /// Optional, for an engine that keeps its settings typed (as ODE and Bullet do): sets them from
  /// the checked values the scene gives (`values`: every declared setting).
  std::function<void(const Descriptor& values, PhysicsSettings& settings)> configure;
  /// Optional, the other way: the typed settings as values (what a scene model prints).
  std::function<void(const PhysicsSettings& settings, Descriptor& values)> describe;
};

/// Adds a physics engine: scenes may name it from then on, and an environment may switch to it.
/// Throws ConfigError when the name is taken or not a word, `create` is missing, or a setting's
/// declaration or default is wrong. Registering is for the start of a program, before scenes load.
SSX_EXPORT void registerPhysicEngine(PhysicEngineClass engine);
/// The engine of that name, or nullptr.
SSX_EXPORT const PhysicEngineClass* findPhysicEngine(std::string_view name);
/// The physics engines this program has: the built-in ones ("ode", "bullet"), then those
/// registered, in order.
SSX_EXPORT std::vector<std::string> physicEngineNames();
/// Creates the engine `settings.engine` names; throws ConfigError for an unknown name or a setting
/// of its own that its declarations refuse.
SSX_EXPORT std::unique_ptr<PhysicEngine> createPhysicEngine(const PhysicsSettings& settings);

}  // namespace ssx
