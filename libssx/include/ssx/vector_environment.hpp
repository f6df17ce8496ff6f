#pragma once
/// @file
/// Many copies of one scene stepped together: the core of learning environments (Python's
/// `ssx.learn.VectorEnv`), usable from C++ alike.
///
/// Each copy is a world of its own (an Environment on one thread): copies cannot touch or sense
/// each other, a copy's trajectory does not depend on its index or on what the other copies do,
/// and resetting one changes no bit of the others. The copies are spread over a pool of worker
/// threads, so a batch is bit for bit the same on any number of threads.

#include <ssx/command.hpp>
#include <ssx/environment.hpp>
#include <ssx/export.hpp>
#include <ssx/scene.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace ssx {

/// One kind of sensor of `robots` (of one environment, or the copies' robots one copy after the
/// other: `per_copy` robots each, named "copy i, robot 'name'" in messages; 0: one environment)
/// into `out`, robots.size() x sensorWidth(...) numbers: the kinds and layouts of
/// VectorEnvironment::sensorWidth. ConfigError as there.
SSX_EXPORT void readSensors(std::span<const Artifact* const> robots, std::string_view kind, std::span<double> out,
                            std::size_t slots = 0, std::size_t per_copy = 0);
/// How many numbers readSensors writes per robot for these robots (VectorEnvironment::sensorWidth).
SSX_EXPORT std::size_t sensorWidth(std::span<const Artifact* const> robots, std::string_view kind,
                                   std::size_t slots = 0);
/// The size of the robots' camera images, {height, width} (VectorEnvironment::imageSize).
SSX_EXPORT std::array<std::size_t, 2> imageSize(std::span<const Artifact* const> robots);
/// The robots' latest camera images into `out`, robots.size() x height x width x 3 bytes
/// (VectorEnvironment::cameraImages).
SSX_EXPORT void cameraImages(std::span<const Artifact* const> robots, std::span<std::uint8_t> out);

/// The state of one robot as a learning environment reads it, in the order of its 13 numbers.
inline constexpr std::size_t kRobotStateSize = 13;  ///< x y z, qw qx qy qz, vx vy vz, wx wy wz

/// Copies of one scene, each a world of its own on one thread, stepped together on a pool of
/// worker threads; reset, reseeded, read and commanded as one batch (see the file comment).
class SSX_EXPORT VectorEnvironment {
 public:
  /// `count` copies, copy i made by `load(i)` (a scene loaded with one thread: SceneOptions::threads
  /// = 1; ConfigError otherwise), started; all copies must have the same robots (the artifacts whose
  /// driver takes set-points, by name, in order: ConfigError naming the first that differs).
  /// `threads`: worker threads that step the copies (0: one per core).
  VectorEnvironment(const std::function<Scene(std::size_t)>& load, std::size_t count, int threads = 0);
  ~VectorEnvironment();
  VectorEnvironment(const VectorEnvironment&) = delete;
  VectorEnvironment& operator=(const VectorEnvironment&) = delete;

  /// How many copies.
  std::size_t size() const noexcept { return envs_.size(); }
  /// Copy `i` (std::out_of_range past size()).
  Environment& operator[](std::size_t i);
  /// Worker threads stepping the copies (the calling thread included).
  unsigned threadCount() const noexcept;
  /// The robots of every copy: the artifacts whose driver takes set-points, in artifact order.
  const std::vector<std::string>& robotNames() const noexcept { return robot_names_; }

  /// Steps every copy `n` times, in parallel: copy i ends as `(*this)[i].step(n)` alone would.
  /// `active`, when not empty, has one flag per copy: only the copies flagged non-zero step (the
  /// others stay where they are: a learning environment's copies being reset). A step that throws
  /// in copy i throws StepError "copy i: ..." (the first copy that failed, by index) once every
  /// copy has stopped; the copies that did not fail went on to the end.
  void step(std::int64_t n, std::span<const std::uint8_t> active = {});
  /// What one learning step gives the copies and reads back (VectorEnvironment::step with it).
  struct StepIO {
    CommandLevel level = CommandLevel::Position;  ///< the commands' level
    std::span<const double> commands;  ///< size() x robots rows of `columns` numbers, as setCommands (empty: none)
    std::size_t columns = 0;           ///< numbers per row of `commands`
    std::span<double> states;          ///< robotStates's output after the steps (empty: not read)
    std::span<double> imu;             ///< imuReadings's output after the steps (empty: not read)
  };
  /// A learning step in one pass over each copy, while its memory is at hand (a thousand copies
  /// do not fit in the caches: passes of their own for commands and readings cost a tenth of a
  /// Crazyflie's steps): as setCommands, step(n, active), robotStates and imuReadings one after
  /// another, except that the copies left out by `active` are not sent their rows (they are
  /// checked all the same); what a copy was sent before a reset, the reset restores over, so a
  /// copy being reset takes its first command with its first step. Every row and output size is
  /// checked before any copy changes (ConfigError as setCommands, robotStates, imuReadings).
  void step(std::int64_t n, std::span<const std::uint8_t> active, const StepIO& io);
  /// Checks commands as setCommands does (ConfigError "copy i, robot 'name': ..."), sending none:
  /// for a caller that must know they are taken before it changes anything else.
  void checkCommands(CommandLevel level, std::span<const double> values, std::size_t columns);
  /// Calls `fn(i)` for every copy i in parallel, on the worker threads (each i once).
  void forEach(const std::function<void(std::size_t)>& fn);

  /// Restores copy `which[k]` to `state` (saved from any copy: they are the same scene) and
  /// reseeds its random streams with `seeds[k]` (Environment::reseed), in parallel. StateError for
  /// a state of another scene, before any copy changes.
  void reset(std::span<const std::size_t> which, std::span<const std::byte> state,
             std::span<const std::uint64_t> seeds);

  /// Every robot of every copy into `out` (size() x robots x kRobotStateSize doubles, in that
  /// order): its root's position, orientation, linear and angular velocity (world frame), as
  /// published after the last step.
  void robotStates(std::span<double> out) const;
  /// Every robot's latest IMU reading into `out` (size() x robots x 6 doubles: accelerometer in
  /// m/s^2, gyroscope in rad/s, body frame, noise and all), from its first IMU sensor. ConfigError
  /// naming the first robot that has none.
  void imuReadings(std::span<double> out) const;
  /// How many numbers readSensors(kind, out, slots) writes per robot. The kinds, each from a
  /// robot's first sensor (or driver) of that kind:
  /// - `pose`: 13, its motion capture (PoseMeasurement, noise and all): position, orientation
  ///   w x y z, linear and angular velocity, world frame;
  /// - `imu`: 6, accelerometer (m/s^2) then gyroscope (rad/s), body frame (as imuReadings);
  /// - `proximity`: one per ray, its reading 0..1 (0: nothing within range);
  /// - `ground`: one per point, its grey level 0..1;
  /// - `range`: 5 per slot, the `slots` nearest robots or obstacles seen: 1 (0: an empty slot,
  ///   all zeros), relative x y z (m; world or body frame as the sensor is set), distance (m);
  /// - `range_and_bearing`: 4 per slot, the first `slots` messages received (in sender order):
  ///   1 (0: empty), range (m), bearing, elevation (rad);
  /// - `odometry`: 9, its driver's dead reckoning (ssx/odometry.hpp, in the order of Odometry's fields).
  /// ConfigError for another kind, a robot without such a sensor, robots whose rays or points
  /// differ in number, or a proximity or ground sensor that has not measured yet (step first).
  std::size_t sensorWidth(std::string_view kind, std::size_t slots = 0) const;
  /// Every robot's latest reading of one kind into `out` (size() x robots x sensorWidth(kind,
  /// slots) doubles, in that order). Read between steps.
  void readSensors(std::string_view kind, std::span<double> out, std::size_t slots = 0) const;
  /// The size of every robot's camera image, {height, width} in pixels, from its first camera
  /// sensor (CameraMeasurement). ConfigError naming the first robot that has none, whose camera
  /// has not drawn yet (step first: a camera draws every `period` steps, with a render engine
  /// that draws pixels), or whose image differs in size from robot 0's.
  std::array<std::size_t, 2> imageSize() const;
  /// Every robot's latest camera image into `out` (size() x robots x height x width x 3 bytes:
  /// RGB, rows from the top), the copies in parallel. ConfigError as imageSize(), or for another
  /// size of `out`.
  void cameraImages(std::span<std::uint8_t> out) const;
  /// Every copy keeps the contacts of its steps from now on (Environment::recordContacts).
  void recordContacts(bool on = true);
  /// Every robot's contacts in the last step into `out` (size() x robots x 2 doubles): the normal
  /// impulse (N s) it took from the static world (the ground, obstacles), and from other bodies
  /// (robots, items). Error when the copies do not record contacts.
  void contactImpulses(std::span<double> out) const;
  /// Per body of a copy (the same in every copy): the robot it belongs to, or -1.
  const std::vector<int>& robotOfBody() const noexcept { return robot_of_body_; }
  /// Moves every robot of copy `which[k]` by `offsets` (which.size() x robots x 3, m, world frame)
  /// and sets its linear velocity to `velocities` (the same shape, m/s; empty: at rest), its
  /// angular velocity to zero; its orientation stays. Every body of a robot moves together. For
  /// start states drawn at reset. ConfigError for a wrong size or a number not finite, before
  /// any body moves; Error when Environment::setBodyState refuses a state (beyond the speed guards).
  void moveRobots(std::span<const std::size_t> which, std::span<const double> offsets,
                  std::span<const double> velocities);
  /// The same command level for every robot of every copy: `values` holds size() x robots rows of
  /// `columns` numbers (the order of ssx/command.hpp). Every row is checked (its size, finite, what
  /// its robot takes) before any robot gets one; ConfigError "copy i, robot 'name': ..." otherwise.
  void setCommands(CommandLevel level, std::span<const double> values, std::size_t columns);
  /// Actuation latency: robot r of copy `which[k]` takes each command setCommands gives it
  /// `steps[k * robots + r]` physics steps into the steps that follow (0, the default: at once),
  /// holding the one before until then; a learning environment's latency, drawn at reset. A
  /// delay longer than the steps between two commands: the earlier takes effect when the later
  /// is given. ConfigError for a wrong size or a negative delay, before any copy changes. The
  /// commands waiting are not in a copy's saved state: reset() drops them (the delays stay).
  void setCommandDelays(std::span<const std::size_t> which, std::span<const std::int64_t> steps);
  /// What vary takes for robot `robot` (Environment::variables of its artifact in copy 0; every
  /// copy is the same scene). std::out_of_range past robotNames().
  std::vector<Variable> variables(std::size_t robot) const;
  /// Sets constant `name` of every robot of copy `which[k]` to `values[k * robots + r]`
  /// (Environment::vary: `mass`, `inertia`, or a variable of its plugins), in parallel: a learning
  /// environment's domain randomisation, drawn at reset. Every value is checked (the robot has
  /// the constant, the value is within its range) before any copy changes; ConfigError "copy i,
  /// robot 'name': ..." otherwise.
  void vary(std::span<const std::size_t> which, std::string_view name, std::span<const double> values);

 private:
  struct Pool;
  // ConfigError for a copy in `which` past size() or named twice
  void checkWhich(std::span<const std::size_t> which, const char* what) const;
  // fn(which[k], k) for every k in parallel (every copy, fn(i, i), for `which` empty), the first
  // failure by copy index rethrown as that copy's
  void forEachOf(std::span<const std::size_t> which, const std::function<void(std::size_t, std::size_t)>& fn);
  // a callable held by reference, called without allocating (a std::function of a lambda with a
  // few captures allocates: once per batch step)
  template <class... Args>
  class Ref {
   public:
    template <class F>
    Ref(const F& f)  // NOLINT(google-explicit-constructor): lambdas are passed as they are
        : fn_(&f), call_([](const void* fn, Args... args) { (*static_cast<const F*>(fn))(args...); }) {}
    void operator()(Args... args) const { call_(fn_, args...); }

   private:
    const void* fn_;
    void (*call_)(const void*, Args...);
  };
  // fn(i) for every copy in parallel, each thread taking runs of copies and asking for the next
  // copy's memory while fn runs (its hot lines); failures as forEachOf
  void forEachInChunks(Ref<std::size_t> fn);
  // the first failure of the last forEach by copy index, rethrown as that copy's (errors cleared)
  void rethrowFirst();
  // copy i's hot lines (Environment::hotMemory), again after it was restored
  void findHotLines(std::size_t i);
  // fn(begin, end) over the copies [0, size()) in chunks, on the worker threads (the first
  // exception fn throws is rethrown: not by copy index, as forEachOf does)
  void forChunks(Ref<std::size_t, std::size_t> fn) const;
  // the command row r (copy r / robots, robot r % robots) sends now
  void send(std::size_t r, const Command& command);
  // builds row r's command from `row` into staged_[r]: what is wrong with it ("" when nothing)
  std::string stageCommand(std::size_t r, CommandLevel level, std::span<const double> row);
  // every row into staged_, checked (ConfigError for the first copy with a problem)
  void stageCommands(CommandLevel level, std::span<const double> values, std::size_t columns);
  // copy i's staged rows sent (or set waiting, for robots with a delay)
  void deliverCommands(std::size_t i);
  // the robots of copies [begin, end) into `out` (robotStates's layout, from copy `begin`)
  void readStates(std::size_t begin, std::size_t end, double* out) const;
  void readImu(std::size_t begin, std::size_t end, double* out) const;
  // ConfigError unless `out` holds `width` numbers per robot of every copy
  void checkOutput(std::span<const double> out, std::size_t width, const char* what) const;
  void checkImus() const;
  // copy i's n steps, with the commands waiting (setCommandDelays) sent when they are due
  void stepCopy(std::size_t i, std::int64_t n);
  std::vector<Scene> scenes_;
  std::vector<Environment*> envs_;
  std::vector<std::string> robot_names_;
  std::vector<const Artifact*> artifacts_;  // per copy, per robot
  // per copy, per robot: the root node read by robotStates and the driver commanded
  std::vector<const PhysicNode*> roots_;
  std::vector<SetpointInterface*> setpoints_;
  std::vector<CommandInterface*> commands_;
  std::vector<std::vector<int>> bodies_;  // per copy, per robot: its moving bodies
  std::vector<const Sensor*> imus_;       // per copy, per robot: its first IMU sensor, or nullptr
  // per robot (every copy is the scene of copy 0): the command levels its driver takes (bit
  // 1 << level) and its rotors, asked once: checking a batch's commands touches no driver
  std::vector<std::uint8_t> accepts_;
  std::vector<std::size_t> rotor_counts_;
  std::vector<int> robot_of_body_;        // per body of a copy: its robot, or -1
  // actuation latency (setCommandDelays; all empty until it is first called), per copy per robot:
  // the delay in steps, the steps until the waiting command is sent (-1: none waits), the command
  std::vector<std::int64_t> delays_, remaining_;
  std::vector<Command> waiting_;
  std::vector<std::uint8_t> copy_waits_;  // per copy: a command of one of its robots waits
  std::vector<Command> staged_;           // setCommands's, per copy per robot (kept: no allocation per call)
  // per copy, the cache lines its next step reads first (Environment::hotMemory), kHotLines a
  // copy, hot_count_[i] of them used: read in order, with no load waiting on another
  static constexpr std::size_t kHotLines = 256;
  std::vector<const char*> hot_lines_;
  std::vector<std::uint16_t> hot_count_;
  mutable std::vector<std::string> problems_;  // setCommands's and cameraImages's, per copy
  std::unique_ptr<Pool> pool_;
};

}  // namespace ssx
