#pragma once
/// @file
/// Environment: owns the engines, the artifacts and the extensions; steps and paces them.
///
/// One step (`step()`), advancing simulated time by one timestep:
///   0. the switches of physics engine due by now (switchPhysicsAt), in the order given
///   1. extensions' beforeStep (calling thread)
///   2. physics: the engine integrates the timestep (in `substeps` parts) with the forces the
///      drivers wrote before and the joints' motors; ghosts move to their next poses; no plugin
///      code runs
///   3. snapshot: every body's new pose, velocities and accelerations are published read-only and
///      checked for NaN / infinity; the neighbour index is marked stale (rebuilt by the first
///      query that needs it) and the engine readies its ray queries; then the images the sensors
///      asked for last step (camera requests) are rendered
///   4. sensors, in parallel over artifacts: each due sensor reads the snapshot and writes its
///      own measurement
///   5. drivers, in parallel over artifacts: each artifact's subscribed callbacks get the fresh
///      measurements (ordered by source artifact, sensor, subscription), then its driver runs
///      if due and writes its own command buffer; then the joints the drivers asked for (attach
///      requests) are made, at the poses they saw
///   6. render, when due: render items are posed from the snapshot and a frame is drawn
///   7. extensions' afterStep (calling thread), then the step listeners (addStepListener)
/// A plugin that throws, or a non-finite state, abandons the step with a StepError; the
/// environment is then failed and refuses further steps. `step()` never sleeps: pacing is in
/// `run()`.

#include <ssx/artifact.hpp>
#include <ssx/class_loader.hpp>
#include <ssx/descriptor.hpp>
#include <ssx/export.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/plugin.hpp>
#include <ssx/pose_stream.hpp>
#include <ssx/render.hpp>
#include <ssx/run_control.hpp>
#include <ssx/spatial_index.hpp>
#include <ssx/timing.hpp>
#include <ssx/types.hpp>
#include <ssx/variation.hpp>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace ssx {

namespace detail {
struct World;
class WorkerPool;
class SceneCameras;
class NeighborIndex;
class Ghosts;
}

/// Everything that defines an environment before it is populated.
/// Limits that keep time arithmetic (integer nanoseconds) in range, checked where the values are
/// given: the scene loader with file:line, the Environment and run() with a ConfigError.
inline constexpr double kMaxTimestepSeconds = 1.0;    ///< one physics step
inline constexpr double kMaxDurationSeconds = 1e9;    ///< about 31 years of simulated time
inline constexpr double kMinRealtimeFactor = 1e-3;    ///< a thousand times slower than real time
inline constexpr double kMaxRealtimeFactor = 1e6;     ///< a million times faster than real time
inline constexpr double kMinRateHz = 1e-6;            ///< a rate (frames, loops) that is not 0: about one per 12 days

/// The scene's wind (`<wind>`): the air every robot whose driver models it flies through, each
/// robot with its own seeded turbulence. A robot's own wind parameters override it value by value.
struct WindSettings {
  Vec3 mean = Vec3::Zero();            ///< m/s, world frame
  Vec3 gust = Vec3::Zero();            ///< m/s, amplitude of one 1-cosine gust
  double gust_start = 0;               ///< s
  double gust_duration = 1;            ///< s
  double turbulence_w20 = 0;           ///< m/s at 20 ft, Dryden (MIL-F-8785C); 0: none
  double turbulence_min_airspeed = 1;  ///< m/s
};

/// What an environment is made with: its clock, seed, threads, engines and wind. Fixed once the
/// environment exists (settings()).
struct EnvironmentSettings {
  Nanoseconds timestep = 1'000'000;  ///< tau, ns (default 1 ms)
  std::uint64_t seed = 0;            ///< root of every random stream
  int threads = 0;                   ///< worker threads for the parallel phases; 0: one per core; 1: inline
  /// Steps whose timing is kept (timing()), in a ring allocated when the environment is made.
  /// 0: none, and no clock is read in a step (a learning environment's copies: a twentieth of a
  /// small world's step); timing() then stays empty.
  std::size_t timing_samples = TimingRecorder::kDefaultCapacity;
  PhysicsSettings physics;  ///< the physics engine and its parameters
  RenderSettings render;    ///< the render engine, scene cameras and outputs
  WindSettings wind;        ///< the scene's wind
};

/// How a run is paced.
struct RunOptions {
  /// Paced against the wall clock, or as fast as the machine goes.
  enum class Mode : std::uint8_t {
    RealTime,  ///< one timestep per timestep/realtime_factor of wall-clock time
    Fast,      ///< as fast as possible
  };
  /// What a real-time run does after a step that finished past its deadline.
  enum class Overrun : std::uint8_t {
    CatchUp,  ///< deadlines stay on the original grid; late steps run back to back until caught up (the paper's)
    Resync,   ///< after a late step the grid restarts from now: lateness never accumulates
  };
  Mode mode = Mode::RealTime;    ///< real time (default) or as fast as possible
  double realtime_factor = 1.0;  ///< > 1 runs faster than the wall clock
  std::int64_t steps = -1;       ///< stop after this many steps; -1: until `stop` is set
  Overrun overrun = Overrun::CatchUp;  ///< after a late step: catch up (default) or restart the grid
  Nanoseconds spin = 0;                             ///< busy-wait this long before each deadline, for precision
  Nanoseconds warn_interval = 1'000'000'000;        ///< at most one overrun warning per this wall time
  const std::atomic<bool>* stop = nullptr;          ///< set to true (from anywhere) to end the run
  std::function<void(const Environment&)> on_step;  ///< after every step, calling thread
  /// 1-99: a real-time run steps on the calling thread and the worker threads at this SCHED_FIFO
  /// priority, each put back to its own policy when the run returns; 0: their policies as they
  /// are. Under the default policy a thread that sleeps until a deadline can be woken milliseconds
  /// late while other work runs (the development machine: up to 5 ms, docs/cli.md); a FIFO thread is run at once.
  /// Needs permission (root, CAP_SYS_NICE or an RLIMIT_RTPRIO; see realtimePriorityProblem): run
  /// throws before the first step without it. Meant for as many threads as cores, and for scenes
  /// that keep up: while it is late, a run at this priority leaves the cores it uses to nothing
  /// else (the kernel's real-time throttling keeps 5 % for the rest). Ignored when Fast.
  int realtime_priority = 0;
};

inline constexpr int kMinRealtimePriority = 1;   ///< RunOptions::realtime_priority, when on
inline constexpr int kMaxRealtimePriority = 99;  ///< the highest SCHED_FIFO priority

/// Why this process cannot run threads at SCHED_FIFO `priority` (1-99), or "" when it can: tried
/// on a thread of its own that ends at once, so nothing of the process changes. For a program to
/// check RunOptions::realtime_priority before it loads or opens anything.
SSX_EXPORT std::string realtimePriorityProblem(int priority);

/// How serious a message is.
enum class LogLevel : std::uint8_t { Info, Warning, Error };
/// Receives every message of an environment (Environment::setLogSink): its level and its text,
/// without a trailing newline. Called on the stepping thread.
using LogSink = std::function<void(LogLevel, std::string_view)>;

/// A simulated world. Not copyable. All calls come from one thread (the one that steps);
/// plugin callbacks run on worker threads only inside the parallel phases.
class SSX_EXPORT Environment {
 public:
  /// Where an environment is in its life: being set up, running (after start() or the first
  /// step), stopped (after stop()), or failed (a step threw; only stop() and queries remain).
  enum class State : std::uint8_t { Setup, Running, Stopped, Failed };

  /// An empty environment with these settings (checked: ConfigError for a timestep, thread count,
  /// engine name or render setting out of range).
  explicit Environment(EnvironmentSettings settings = {});
  Environment(const Environment&) = delete;
  Environment& operator=(const Environment&) = delete;
  /// Stops (if running) and destroys everything: plugins, engines, then extensions.
  ~Environment();

  // --- setup -------------------------------------------------------------------------------

  /// Adds an artifact placed at `placement`. Names are unique (ConfigError otherwise).
  Artifact& addArtifact(std::string name, const Pose& placement = {});
  /// Adds a static ground plane at height `z` (an artifact named "ground").
  Artifact& addGround(double z = 0.0);
  /// Adds an extension under a unique name, before start: it is part of the scene, its saveState
  /// in every saved state (a state restores only into an environment with the same extensions).
  /// While running it attaches an observer (attachExtension).
  SimulationExtension& addExtension(std::string name, std::unique_ptr<SimulationExtension> extension,
                                    Descriptor params = {});
  /// Same, for an extension owned elsewhere (by classLoader()).
  SimulationExtension& addExtension(std::string name, SimulationExtension& extension, Descriptor params);
  /// Adds an observer: an extension that looks at or steers the run from outside (a viewer, a
  /// bridge), before start (initialised with the others) or while running, between steps (its
  /// parameters checked as at start, then its init at once, its hooks from the next step on; an
  /// init that throws attaches nothing). It is not part of saved states (its saveState and
  /// loadState are not called) nor of what a state must match, so a state saved with it restores
  /// without it and the other way round; removeExtension takes it off again between steps.
  /// Error from inside a step (an extension's hook, a listener), or once stopped or failed.
  SimulationExtension& attachExtension(std::string name, SimulationExtension& extension, Descriptor params);
  /// Takes the extension named `name` out again: before the environment starts (a start that
  /// failed leaves it in setup), the environment is as it was before it was added; while running,
  /// between steps, an observer (attachExtension) is shut down at once (Error with what its
  /// shutdown threw, the extension taken off all the same). False when there is none by that
  /// name; Error for one that is part of the scene (addExtension before start) while running.
  bool removeExtension(std::string_view name);
  /// The loader for plugin libraries; it owns what it creates, and the environment destroys
  /// those instances right after its plugins' destroy() and before anything else.
  ClassLoader& classLoader() noexcept { return *loader_; }
  /// Delivers `sensor`'s measurements to `callback`, in the drivers phase on `subscriber`'s
  /// thread. Allowed before start and from `configure`.
  void subscribe(const Sensor& sensor, Artifact& subscriber, std::function<void(const Measurement&)> callback);
  /// Typed form: the sensor's measurement must be an M (checked now).
  template <class M>
  void subscribe(const Sensor& sensor, Artifact& subscriber, std::function<void(const M&)> callback);
  /// Where messages go (default: stderr, "ssx: warning: ...").
  void setLogSink(LogSink sink);
  /// Sends a message to the log sink (by default: stderr). Plugins log through this.
  void log(LogLevel level, std::string_view message) const;

  // --- lifecycle -----------------------------------------------------------------------------

  /// Inits extensions, configures the engines, publishes the first snapshot, configures drivers
  /// and sensors, starts the worker pool. Called by the first step() if not called before.
  void start();
  /// Advances one timestep (see the file comment). Throws StepError if a plugin fails.
  void step();
  /// Steps `n` times.
  void step(std::int64_t n);
  /// Runs and paces steps; returns the timing summary of this run. Throws StepError.
  TimingSummary run(const RunOptions& options);
  /// Destroys drivers and sensors, stops the engines, finishes frames and videos, shuts
  /// extensions down (reverse order). All of it happens even when a part fails; then it throws
  /// Error naming every part that failed (a plugin's destroy, a video ffmpeg could not finish, a
  /// file an extension could not write to the end).
  void stop();

  // --- save and restore --------------------------------------------------------------------

  /// Everything that determines the future, between two steps: the physics engine's state (with
  /// its random seed), the snapshot, the command buffers, every random stream, every plugin's
  /// and extension's own state (their saveState), the step count. A versioned, checksummed
  /// buffer. Starts nothing: the environment must be running (after start() or a step).
  std::vector<std::byte> saveState() const;
  /// The same into `into`, over what it holds: a buffer kept from the last state saves the
  /// allocation and the first touch of its memory (a recorder saving every few seconds).
  void saveState(std::vector<std::byte>& into) const;
  /// Continues from a saved state: the next steps are bitwise those of the run that saved it,
  /// on any number of threads, also in another process that loaded the same scene. Starts the
  /// environment first if it is still being set up. A truncated, corrupted or mismatched buffer
  /// throws StateError and leaves the state as it was. It continues on the engine that saved it
  /// (switching as switchPhysics does). Not saved: camera images and extensions' outside world.
  void restoreState(std::span<const std::byte> state);
  /// The checks restoreState makes before it changes anything (format, size, checksum, the scene
  /// it was saved from), without starting the environment. Throws StateError.
  void checkState(std::span<const std::byte> state) const;
  /// Where the environment is in its life.
  State state() const noexcept;
  /// Restarts every plugin's random stream (sensor noise, wind gusts, a driver's draws) as a scene
  /// loaded with `seed` would start it: stream (artifact i, plugin j) from deriveSeed(seed, i, j).
  /// Between two steps, after restoreState for instance, so that episodes started from one saved
  /// state draw other noise (a learning environment's reset). What the streams already drew, and
  /// the scene's placement and settings().seed, stay as they are.
  void reseed(std::uint64_t seed);

  // --- exchanging the physics engine while running ------------------------------------------

  /// Continues the run on another physics engine (one of physicEngineNames()), between two
  /// steps: every body's pose and velocities, the joints of the scene and those made at run time
  /// (attachments) with their motors' commands, the ghosts, the drivers' and sensors' state and
  /// the commands held for the next step carry over; the new engine finds the contacts again in
  /// its first step (what an engine keeps between steps for itself, ODE's partitions and their
  /// random seeds, starts afresh). Deterministic: the same switches at the same steps give the
  /// same bits on any thread count. Before start it chooses the engine the run starts with; the
  /// engine already stepping changes nothing. ConfigError for an unknown engine; Error from the
  /// parallel phases or configure, or once the environment failed or stopped.
  void switchPhysics(const std::string& engine);
  /// The same, carried out just before the first step that starts at or after `time` (ns of
  /// simulated time; now or earlier: before the next step): for a command line's
  /// `--switch-physics` and a re-simulation replaying a recorded run's switches. Several at one
  /// time are carried out in the order given. ConfigError for an unknown engine or a negative time.
  void switchPhysicsAt(Nanoseconds time, const std::string& engine);
  /// The switches switchPhysics and switchPhysicsAt made so far, in order (restoring a state
  /// saved by another engine is not one: the state says its engine).
  const std::vector<PhysicsSwitch>& physicsSwitches() const noexcept { return switches_; }

  // --- queries -------------------------------------------------------------------------------

  /// The settings it was made with; `physics.engine` is the engine stepping now (switchPhysics).
  const EnvironmentSettings& settings() const noexcept { return settings_; }
  /// The physics timestep tau, ns.
  Nanoseconds timestep() const noexcept { return settings_.timestep; }
  /// Simulated time: steps taken times the timestep.
  Nanoseconds time() const noexcept { return stepCount() * settings_.timestep; }
  /// Steps taken so far (restoreState sets it to the saved run's).
  std::int64_t stepCount() const noexcept;
  /// Worker threads used by the parallel phases (1: inline).
  unsigned threadCount() const noexcept;

  /// How many artifacts the environment has (the ground included).
  std::size_t artifactCount() const noexcept;
  /// Artifact `index`, in the order added (std::out_of_range past artifactCount()).
  Artifact& artifact(std::size_t index);
  /// @copydoc artifact(std::size_t)
  const Artifact& artifact(std::size_t index) const;
  /// Artifact by name, or nullptr.
  Artifact* findArtifact(std::string_view name);
  /// @copydoc findArtifact(std::string_view)
  const Artifact* findArtifact(std::string_view name) const;
  /// Artifacts chosen by a parameter: "*" is every artifact with a dynamic root, else names separated
  /// by spaces, each of an artifact with a physic root. Throws Error naming the first name that is not.
  std::vector<Artifact*> selectArtifacts(std::string_view names);
  /// @copydoc selectArtifacts(std::string_view)
  std::vector<const Artifact*> selectArtifacts(std::string_view names) const;
  /// The same for the names a plugin parameter `key` gives; throws the parameter's ConfigError,
  /// "... to <purpose>", when a name does not fit.
  std::vector<Artifact*> selectArtifacts(const Descriptor& params, std::string_view key, std::string_view purpose);
  /// @copydoc selectArtifacts(const Descriptor&, std::string_view, std::string_view)
  std::vector<const Artifact*> selectArtifacts(const Descriptor& params, std::string_view key,
                                               std::string_view purpose) const;
  /// Extension by name, or nullptr.
  SimulationExtension* extension(std::string_view name) const;
  /// Every extension's name, in the order added.
  std::vector<std::string> extensionNames() const;
  /// Extension by name as a T, or nullptr (no such extension, or one of another type).
  template <class T>
  T* extension(std::string_view name) const {
    return dynamic_cast<T*>(extension(name));
  }

  /// The published state of body `i` (see PhysicNode::bodyIndex).
  const BodyState& bodyState(int i) const;
  /// How many rigid bodies the world has: one per dynamic physic node tree (static trees have none).
  std::size_t bodyCount() const noexcept;
  /// Sets body `i`'s pose and velocities (centre-of-mass frame, world) between steps, in the engine and the
  /// snapshot (accelerations kept): to reset or teleport a robot, not from plugins during a step. Throws
  /// Error for a static or unknown body, a non-finite state or one faster than the speed guards.
  void setBodyState(int i, const BodyState& state);
  /// A 64-bit hash (FNV-1a) of every body's pose and velocities, bit for bit, and the time.
  std::uint64_t stateHash() const;
  /// Appends the memory the next step reads first (tables, artifacts, plugins, bodies), to prefetch while
  /// another environment steps (VectorEnvironment); until a restore; none past 16 artifacts.
  void hotMemory(std::vector<MemoryRange>& out) const;
  /// The artifact body `i` belongs to (std::out_of_range for another index).
  const Artifact& bodyOwner(int i) const;
  /// Keeps the contacts of every step from now on (on), or stops (off: the default, since a swarm
  /// resting on the ground makes thousands a step); kept across engine switches, not part of the
  /// saved state. Between steps.
  void recordContacts(bool on = true);
  /// The contacts of the last step taken while recording (PhysicEngine::contacts: one per pair of
  /// bodies, or a body and the static world, with the normal impulse); empty after restoreState
  /// until the next step. Throws Error when not recording.
  const std::vector<EngineContact>& contacts() const;
  /// What body_a of `contact` touched: the artifact of body_b, or for a static shape (body_b -1) the
  /// static artifact it belongs to (the ground, a wall). std::out_of_range for another environment's.
  const Artifact& contactOther(const EngineContact& contact) const;

  // --- variations: constants that change between episodes (ssx/variation.hpp) --------------

  /// What `vary` takes for `artifact`: `mass` and `inertia` (when it has a moving body), then its
  /// plugins' variables (driver first, then sensors; a name two plugins give goes to the first).
  std::vector<Variable> variables(const Artifact& artifact) const;
  /// Sets constant `name` of `artifact` to `value` from the next step on (a learning
  /// environment's domain randomisation): `mass` and `inertia` are factors on each of its bodies'
  /// mass and inertia as the scene gave them; any other name is a variable of one of its plugins
  /// (VariationInterface). Part of the saved state; restoring a state sets every varied constant to
  /// the state's value. Between steps only. ConfigError for an unknown name (listing the known
  /// ones) or a value outside the variable's range, before anything changes.
  void vary(const Artifact& artifact, std::string_view name, double value);
  /// The value `name` has now for `artifact` (its neutral value when never varied).
  double variation(const Artifact& artifact, std::string_view name) const;

  // --- artifacts out of the world and back (scene-format.md: present="false") -----------------
  /// Takes a moving artifact out of the world, before start or between steps: its bodies stay put,
  /// touch nothing, meet no ray (PhysicEngine::setEnabled); its plugins do not run, neighbour
  /// queries miss it, Artifact::present() is false; nothing is renumbered. Part of the saved state.
  /// Error for a static artifact, a ghost, one attached to another, or one out already.
  void despawn(Artifact& artifact);
  /// Puts it back between steps, its root frame at `pose` (world), at rest; its plugins go on from
  /// their state. Error for one in the world, a pose not finite or not of unit length, before start.
  void spawn(Artifact& artifact, const Pose& pose);

  // --- ghosts: real robots inside the simulation --------------------------------------------

  /// Makes `artifact` a ghost (before start): a robot whose pose comes from outside, a real one's
  /// motion capture. Its body is kinematic: simulated robots collide with it and sense it, nothing
  /// pushes it. At each step it is where its samples (setExternalPose) say at the step's time:
  /// interpolated between them, extrapolated past the newest for at most `settings.horizon`.
  /// With no sample yet, or none for longer than `settings.timeout`, it is lost: it holds where
  /// it was, its sensors do not measure, and the log says so. Its sensors measure the simulated
  /// world for the real robot. ConfigError for an artifact of another environment, one that is not
  /// one dynamic physic tree, or one with a driver (a ghost moves by its samples alone).
  void setGhost(Artifact& artifact, const PoseStream::Settings& settings = {});
  /// Whether the artifact is a ghost.
  bool isGhost(const Artifact& artifact) const;
  /// Adds a pose of ghost `name`'s root frame (world frame), measured at simulated time `stamp`
  /// (s). Samples may come late and out of order (see PoseStream). Before start or between steps,
  /// from the thread that steps (the bridges call it in their beforeStep). Error for a name that
  /// is not a ghost's; std::invalid_argument for a non-finite stamp or pose or a quaternion far
  /// from unit length.
  void setExternalPose(std::string_view name, const Pose& pose, double stamp);
  /// What a ghost's pose stream says now.
  struct GhostStatus {
    bool lost = true;          ///< no pose yet, or none for longer than the timeout
    double age = 0;            ///< s: the current time minus the newest sample at or before it
    std::size_t samples = 0;   ///< samples kept
  };
  /// The status of ghost `artifact` (Error for an artifact that is not a ghost).
  GhostStatus ghostStatus(const Artifact& artifact) const;
  /// The ages of the poses the ghosts were placed at, every step of the run so far (while
  /// tracked): median, p99 and maximum.
  AgeSummary ghostAges() const;

  /// Neighbour queries. A plugin that wants them calls enableNeighborQueries from configure (never
  /// from sense, step or a callback: those run in parallel with the queries); from
  /// then on the index of every artifact's first dynamic root position is rebuilt when first
  /// queried after a step (a step without a query builds none; the smallest cell size asked for
  /// wins).
  void enableNeighborQueries(double cell_size);
  /// Whether a plugin enabled neighbour queries.
  bool neighborQueriesEnabled() const noexcept;
  /// Appends to `out` the indices of the artifacts (with a dynamic root) whose first root is
  /// within `radius` of `point`, in ascending order; reads the snapshot's index, so it is safe in
  /// the parallel phases. Throws if queries were not enabled.
  void neighbors(const Vec3& point, double radius, std::vector<std::size_t>& out) const;
  /// Same, with each artifact's indexed position (as of the snapshot), in ascending artifact order.
  void neighbors(const Vec3& point, double radius, std::vector<SpatialIndex::Hit>& out) const;
  /// Calls visit(artifact index, indexed position) for the same artifacts, in no particular order
  /// (the index's; the same in every run): for a plugin that orders what it keeps itself, as a
  /// range sensor sorting by distance, without a list to fill and sort first.
  template <class Visit>
  void forEachNeighbor(const Vec3& point, double radius, Visit&& visit) const {
    forEachNeighbor(
        point, radius,
        [](void* context, std::size_t id, const Vec3& p) { (*static_cast<std::remove_reference_t<Visit>*>(context))(id, p); },
        static_cast<void*>(&visit));
  }
  /// The same with a plain function and its context pointer.
  void forEachNeighbor(const Vec3& point, double radius, SpatialIndex::Visitor visit, void* context) const;

  /// Ray queries, for sensors that cast rays (proximity, occlusion). A plugin that casts rays calls
  /// enableRayQueries from configure; from then on, after each step's physics, the engine poses its
  /// shapes where the snapshot has the bodies.
  void enableRayQueries();
  /// Whether a plugin enabled ray queries.
  bool rayQueriesEnabled() const noexcept { return rays_enabled_; }
  /// Casts each ray against every shape (bodies and static shapes) but those of `ignore`'s bodies
  /// (null: none), with the engine's ray queries; hits[i] is where rays[i] first meets one, as of
  /// the snapshot. Safe in the parallel phases. Throws if queries were not enabled or the sizes differ.
  void castRays(std::span<const Ray> rays, std::span<RayHit> hits, const Artifact* ignore = nullptr) const;

  /// A shape of a static artifact, posed in the world.
  struct StaticShape {
    Shape shape;  ///< its pose is the shape's pose in its static root's frame
    Pose world;   ///< the shape's frame in the world
    std::size_t artifact = 0;  ///< index of the static artifact it belongs to
  };
  /// Every shape of every static root (ground planes included), known from start() on.
  const std::vector<StaticShape>& staticShapes() const noexcept { return static_shapes_; }

  /// The render nodes of the last frame or camera image drawn, posed in the world.
  const std::vector<RenderNode>& renderNodes() const noexcept;
  /// Camera images for sensors. `due(step, view)` is called in the snapshot phase of every step,
  /// on the stepping thread, after the snapshot is published; when it returns true, the view it
  /// filled in is drawn from that step's snapshot into `target`, before the sensors phase (so a
  /// sensor delivers the image of the step it runs in). Call from configure; needs an engine that
  /// draws pixels (ConfigError otherwise). `owner` names the requester in messages.
  void addCameraRequest(std::string owner, std::function<bool(std::int64_t step, CameraView& view)> due,
                        Image& target);
  /// Draws the scene cameras' frame of the world as it is now, stamped with `time`, outside a step:
  /// for a replay that poses the bodies itself (setBodyState) without stepping. Needs the
  /// environment running; a camera that follows a robot follows it. Throws StepError when a frame
  /// cannot be drawn or written. `overlay`: more nodes drawn in this frame only, in the world
  /// (a replay's trails; their specs must live until the frame is written: keep them for the
  /// environment's life); they cast no shadows.
  void drawFrame(Nanoseconds time, std::span<const RenderNode> overlay = {});
  /// Frames drawn for the scene's cameras so far.
  std::int64_t frameCount() const noexcept;
  /// The scene cameras' specs as used (frame_scene cameras placed), while their frames are drawn.
  std::vector<CameraSpec> cameras() const;
  /// Draws the scene cameras' frames with `render` (its engine, cameras, rate, size, outputs and
  /// its window in time, RenderSettings::from and until). Before start it sets what the run starts
  /// with. While running, between steps, it attaches a renderer to the run: the frames being drawn
  /// are finished first (as detachRenderer does), then the new ones are drawn from the next step
  /// (or `render.from`, if later) on, every `period_steps` from there; their outputs are opened
  /// and the framing cameras placed now (at `from` when that is later). Pictures change nothing
  /// in the world: the same run gives the same bits with or without them, attached and detached at
  /// any steps. Camera sensors keep drawing as they started (engine and background), so while one
  /// does the engine may not change. ConfigError for settings out of range or a camera following
  /// no robot, before anything changes; Error from a step's hooks or listeners, or once stopped.
  void attachRenderer(RenderSettings render);
  /// Stops drawing the scene cameras' frames, between steps: the frames queued are drawn, the
  /// outputs finished (a video closed, a snapshot of the last frame written), the cameras
  /// forgotten; camera sensors go on. Throws Error naming an output that could not be finished
  /// (the run goes on, without frames). Nothing to stop: nothing happens.
  void detachRenderer();

  /// The physics engine, read-only (bodies are added by the environment, at start); throws when
  /// the environment is not running.
  const PhysicEngine& physics() const;
  /// The render engine, read-only; throws when the environment is not running.
  const RenderEngine& renderer() const;
  /// Calls `listener` at the end of every step (after the extensions' afterStep), on the stepping
  /// thread, whether the steps come from step() or run(), until removeStepListener. For observers
  /// outside the simulated world (a recording): listeners are not part of a saved state. A listener
  /// that throws fails the step as a plugin does (StepError). Returns the listener's id.
  std::size_t addStepListener(std::function<void(const Environment&)> listener);
  /// Removes a listener added by addStepListener (an unknown id is ignored).
  void removeStepListener(std::size_t id) noexcept;

  /// Pausing, single steps and the real-time factor of run(), from any thread.
  RunControl& runControl() noexcept { return *run_control_; }
  /// Whether run() is running with a stop flag (RunOptions::stop) that is now set (a Ctrl-C): a
  /// plugin that waits on something outside the simulation (a bridge in lock-step waiting for its
  /// controllers) stops waiting, so that the run ends after the step. Safe from any thread.
  bool stopRequested() const noexcept {
    const std::atomic<bool>* stop = run_stop_.load();
    return stop != nullptr && stop->load();
  }
  /// Per-step timing of every step taken so far.
  TimingRecorder& timing() noexcept { return timing_; }
  /// @copydoc timing()
  const TimingRecorder& timing() const noexcept { return timing_; }

 private:
  void requireSetup(const char* what) const;
  void checkDeclaredParameters();
  void requireOutsidePhases(const char* what) const;
  std::uint64_t sceneFingerprint() const;
  void applyState(std::span<const std::byte> payload, std::uint32_t format);
  // restoreState after checkState passed (VectorEnvironment checks a state once for all its copies)
  void restoreChecked(std::span<const std::byte> state);
  friend class VectorEnvironment;
  void raiseFirstError(const char* phase);
  void fail();
  void warnUnusedParameters() const;
  void runExtensionHook(void (SimulationExtension::*hook)(Environment&), const char* what);
  void exchangePhysics(const std::string& engine);
  void runScheduledSwitches();
  void requireBetweenSteps(const char* what) const;
  void checkPresenceChange(const Artifact& artifact, const char* what) const;
  void checkObserver(const SimulationExtension& extension, Descriptor& params, const std::string& name) const;

  struct ExtensionSlot {
    std::string name;
    SimulationExtension* extension;
    std::unique_ptr<SimulationExtension> owned;  // null when the ClassLoader owns it
    Descriptor params;
    bool initialised = false;
    bool observer = false;  // added while running: not part of saved states nor the fingerprint
  };

  EnvironmentSettings settings_;
  std::unique_ptr<ClassLoader> loader_;  // declared first: destroyed last
  std::unique_ptr<detail::World> world_;  // artifacts, plugin slots, bodies: what the phases work on
  std::vector<ExtensionSlot> extensions_;
  std::unique_ptr<PhysicEngine> physics_;
  std::unique_ptr<RenderEngine> renderer_;
  std::unique_ptr<detail::WorkerPool> pool_;
  std::unique_ptr<detail::SceneCameras> cameras_;  // scene cameras, camera images, render items
  std::unique_ptr<detail::NeighborIndex> neighbors_;
  std::unique_ptr<detail::Ghosts> ghosts_;
  bool rays_enabled_ = false;
  mutable bool rays_stale_ = true;  // the engine's shapes are not where the snapshot has the bodies
  std::vector<StaticShape> static_shapes_;
  std::vector<PhysicsSwitch> switches_, scheduled_;  // made so far; switchPhysicsAt's, by time (`from` unused)
  TimingRecorder timing_{settings_.timing_samples};
  LogSink log_;
  // step listeners (addStepListener), after the members plugins' inline accessors read
  std::vector<std::pair<std::size_t, std::function<void(const Environment&)>>> listeners_;
  std::size_t next_listener_ = 0;
  std::unique_ptr<RunControl> run_control_ = std::make_unique<RunControl>();
  std::atomic<const std::atomic<bool>*> run_stop_{nullptr};  // RunOptions::stop while run() runs
};

template <class M>
void Environment::subscribe(const Sensor& sensor, Artifact& subscriber, std::function<void(const M&)> callback) {
  if (dynamic_cast<const M*>(&sensor.latest()) == nullptr)
    throw ConfigError({}, "sensor '" + sensor.className() + "' of artifact '" + sensor.artifact().name() +
                              "' does not produce the measurement type the subscriber asked for");
  subscribe(sensor, subscriber, [cb = std::move(callback)](const Measurement& m) { cb(static_cast<const M&>(m)); });
}

}  // namespace ssx
