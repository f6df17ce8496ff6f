#pragma once
// What the ROS bridges (plugins/ros1, plugins/ros2) share below the simulation: the messages as
// plain numbers, and a Transport that stages what a step publishes, sends it on a thread of its own
// (serialising and writing never on the stepping thread), and keeps what arrived (each robot's
// newest set-point and velocity command, every pose of a ghost, the round trips, the waits of
// lock-step). A transport
// subclass only sends (send, on the publishing thread), tells whether a robot's peers are there
// (connected), and hands over what it receives (receivedSetpoint, receivedVelocity, receivedPose).
//
// Standard library only, and C++17: the ROS 1 side, whose message headers do not compile as C++20,
// includes it too.
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace ssx::bridge {

struct Odometry {
  double time = 0;                                        // simulated seconds
  std::array<double, 3> position{};                       // world
  std::array<double, 3> velocity{}, angular_velocity{};   // body frame (ROS: the child frame)
  std::array<double, 4> orientation{1, 0, 0, 0};          // w x y z
};

struct Imu {
  double time = 0;
  std::array<double, 3> angular_velocity{}, linear_acceleration{};  // sensor frame
  std::array<double, 4> orientation{1, 0, 0, 0};                     // w x y z (ground truth)
};

struct Setpoint {
  double stamp = 0;  // header.stamp, seconds
  std::array<double, 3> position{};
  std::array<double, 4> orientation{1, 0, 0, 0};  // w x y z
  std::uint64_t count = 0;                        // set-points received so far for this robot
  std::uint64_t order = 0;                        // when it arrived, among every message received
};

struct Velocity {
  std::array<double, 3> linear{}, angular{};  // m/s and rad/s (a Twist: the robot's body frame)
  std::uint64_t count = 0;                    // commands received so far for this robot
  std::uint64_t order = 0;                    // when it arrived, among every message received
};

// A ghost's pose as measured outside (motion capture): every one is kept, in arrival order
struct PoseSample {
  std::size_t robot = 0;
  double stamp = 0;  // header.stamp, seconds (0: unstamped)
  std::array<double, 3> position{};
  std::array<double, 4> orientation{1, 0, 0, 0};  // w x y z
};

struct Joy {
  double stamp = -1;  // header.stamp, seconds (-1: none yet)
  std::vector<float> axes;
  std::vector<int> buttons;
  std::uint64_t count = 0;  // received so far for this operator
  std::uint64_t order = 0;  // when it arrived, among every message received
};

// A robot's joint command (a JointState in): each named joint driven to its position, or, when the
// message has no positions, at its velocity
struct JointCommand {
  std::vector<std::string> names;
  std::vector<double> positions, velocities;  // empty, or one per name (checked when applied)
  std::uint64_t count = 0;  // received so far for this robot
  std::uint64_t order = 0;  // when it arrived, among every message received
};

// A frame fixed in another, for /tf_static: `child` at `pose` (x y z qw qx qy qz) in `parent`
struct StaticFrame {
  std::string parent, child;
  std::array<double, 7> pose{0, 0, 0, 1, 0, 0, 0};
};

struct RobotTopics {
  std::string name;       // the namespace: /<name>/odom, /<name>/imu, /<name>/setpoint, /<name>/cmd_vel
  bool imu = false;       // publishes /<name>/imu
  bool setpoint = false;  // takes /<name>/setpoint
  bool velocity = false;  // takes /<name>/cmd_vel (where the transport offers it)
  bool ghost = false;     // takes /<name>/pose (a real robot's motion capture)
  bool range = false;     // publishes /<name>/range (what its range sensor sees)
  bool odom = true;       // publishes /<name>/odom (every robot; not an operator)
  bool joy = false;       // takes /<name>/joy (an operator)
  bool force = false;     // publishes /<name>/force (an operator: a WrenchStamped)
  bool image = false;     // publishes /<name>/image (what its camera sees: rgb8)
  bool tf = false;        // its frames on /tf: <name>/<root_frame> and each of `parts` (where the transport offers it)
  std::string root_frame = "base_link";  // its root's frame: odometry's child frame, the first on /tf
  std::vector<std::string> parts;   // its other bodies (joined parts): frames <name>/<part> on /tf
  std::vector<std::string> joints;  // its hinges and sliders, by the node each moves: /<name>/joint_states
  std::vector<StaticFrame> statics;  // its frames fixed in its bodies' (a sensor's mount): /tf_static
  std::string description;           // its URDF: /<name>/robot_description (empty: none)
  bool joint_commands = false;       // takes /<name>/joint_command (its `joints`)
  bool scan = false;                 // publishes /<name>/scan (its proximity ring, where the transport offers it)
  std::string scan_frame = "scan";   // the ring's frame (without the robot's prefix; on /tf_static with tf)
  std::string imu_frame = "imu";     // the IMU's frame (likewise)
  std::string camera_frame = "camera";  // the frame of its images and camera_info (likewise: with tf, the optical frame)
  bool ground = false;               // publishes /<name>/ground (ssx_msgs/Ground; where the transport offers it)
  bool range_bearing = false;        // publishes /<name>/range_bearing (ssx_msgs/RangeBearing; likewise)
};

/// One message to send: what the stepping thread stages.
struct Outgoing {
  enum class Kind : std::uint8_t { Clock, Odometry, Imu, Range, Force, Image, Transforms, JointStates, Scan, Ground,
                                  RangeBearing } kind = Kind::Clock;
  std::size_t robot = 0;
  double time = 0;  // the clock's, the range's, the force's
  std::array<double, 3> force{};  // N, world frame
  Odometry odometry;
  Imu imu;
  // a range: its detections' relative positions, [first, first + count) of the points staged with it
  bool body_frame = false;
  std::size_t first = 0, count = 0;
  const std::array<double, 3>* points = nullptr;  // set for send(): the first of them
  // an image: width x height rgb8 pixels, row by row from the top, [first, first + count) of the
  // bytes staged with it
  int width = 0, height = 0;
  double fov_deg = 0;  // the image's horizontal field of view
  const std::uint8_t* bytes = nullptr;  // set for send(): the first of them
  // transforms (7 values a frame: x y z qw qx qy qz in the world, base_link then each part), joint
  // states (2 a joint: position, velocity) and scans (the ring's reach from it and its radius in m,
  // then 3 a ray: direction in rad, distance from the ring in m, +inf for none, and reading 0..1):
  // [first, first + count) of the values staged with it. A ground reading: 4 values a point (grey,
  // red, green, blue). Range-and-bearing: 5 values a message (range, bearing, elevation, the sender's
  // name's length, the payload's length), the names and payloads one after the other in the bytes
  // staged with it from first_byte
  std::size_t first_byte = 0;
  const double* values = nullptr;  // set for send(): the first of them
};

class Transport {
 public:
  explicit Transport(std::vector<RobotTopics> robots);
  virtual ~Transport();
  Transport(const Transport&) = delete;
  Transport& operator=(const Transport&) = delete;

  const std::vector<RobotTopics>& robots() const { return robots_; }

  // Staged for the publishing thread by the stepping thread, which only copies a few numbers and
  // takes no lock; commit() hands what is staged to that thread (one lock and one wake-up per
  // step, not per message). Messages go out in the order staged, with the stamps given.
  void publishClock(double time);
  void publishOdometry(std::size_t robot, const Odometry& odometry);
  void publishImu(std::size_t robot, const Imu& imu);
  // `points`: the detections' positions relative to the robot, nearest first
  void publishRange(std::size_t robot, double time, bool body_frame, const std::vector<std::array<double, 3>>& points);
  void publishForce(std::size_t robot, double time, const std::array<double, 3>& force);
  void publishImage(std::size_t robot, double time, int width, int height, double fov_deg, const std::vector<std::uint8_t>& rgb);
  // a proximity ring: its reach from the ring and radius (m), each ray's direction (rad), distance (m)
  // and reading
  void publishGround(std::size_t robot, double time, const std::vector<double>& values);
  // values: 5 a message as in Outgoing; bytes: each message's sender name then payload
  void publishRangeBearing(std::size_t robot, double time, const std::vector<double>& values,
                           const std::vector<std::uint8_t>& bytes);
  void publishScan(std::size_t robot, double time, double reach, double radius, const std::vector<double>& angles,
                   const std::vector<double>& distances, const std::vector<double>& readings);
  // `poses`: 7 values a frame (x y z qw qx qy qz, world), the robot's base_link then each of its parts
  void publishTransforms(std::size_t robot, double time, const std::vector<double>& poses);
  // `values`: 2 a joint (position, velocity), in the order of the robot's `joints`
  void publishJointStates(std::size_t robot, double time, const std::vector<double>& values);
  void commit();
  // Waits until everything staged so far has been sent.
  void flush();
  // The newest set-point and velocity command of a robot (count 0: none yet). Thread-safe.
  Setpoint latestSetpoint(std::size_t robot) const;
  Velocity latestVelocity(std::size_t robot) const;
  Joy latestJoy(std::size_t robot) const;
  JointCommand latestJointCommand(std::size_t robot) const;
  // How many set-points and velocity commands arrived so far, for all robots (without a lock: a
  // step that sees the same number as the last skips the look-ups).
  std::uint64_t received() const { return received_count_.load(std::memory_order_acquire); }
  // Moves the ghosts' poses received since the last call to `out` (cleared first), in arrival order.
  // At most kMaxPosesQueued wait per robot: beyond, the oldest are dropped (posesDropped counts them).
  void takePoses(std::vector<PoseSample>& out);
  static constexpr std::size_t kMaxPosesQueued = 1024;
  std::uint64_t posesDropped() const;
  // Waits until every robot with a set-point topic has one stamped at or after `time` (seconds),
  // every ghost a pose and every operator a joystick state, at most `timeout_s`; returns the names
  // of those still missing (empty: all there). Gives up early when `stop` (looked at every 20 ms)
  // says so: a Ctrl-C ends a run waiting here.
  std::vector<std::string> waitForSetpoints(double time, double timeout_s, const std::function<bool()>& stop) const;
  // Waits until every robot that takes set-points or poses, and every operator, has its peers (connected()), at most
  // `timeout_s` or until `stop`; returns the names of the robots still unconnected.
  std::vector<std::string> waitForPeers(double timeout_s, const std::function<bool()>& stop) const;
  // Round trips in wall-clock seconds: from sending the odometry of time t (robot 0's) to receiving
  // a set-point stamped t (one sample per set-point that answers an odometry message).
  std::vector<double> roundTrips() const;
  // Sends what is staged, then stops the publishing thread (idempotent). A subclass calls it first
  // in its own shutdown, before it tears down what send() uses.
  void stopPublishing();

 protected:
  // Starts the publishing thread: a subclass calls it once what send() uses exists.
  void startPublishing();
  // Sends one message (on the publishing thread).
  virtual void send(const Outgoing& message) = 0;
  // After send() was given every message of a batch (on the publishing thread): what a subclass
  // gathers across robots goes out here (ROS 2's /tf: one message for all).
  virtual void batchSent() {}
  // Whether robot `robot`'s controller is there: someone reads its odometry and writes its set-points.
  virtual bool connected(std::size_t robot) const = 0;
  // What a subclass received, from any thread.
  void receivedSetpoint(std::size_t robot, double stamp, const std::array<double, 3>& position,
                        const std::array<double, 4>& orientation_wxyz);
  void receivedVelocity(std::size_t robot, const std::array<double, 3>& linear, const std::array<double, 3>& angular);
  void receivedPose(std::size_t robot, double stamp, const std::array<double, 3>& position,
                    const std::array<double, 4>& orientation_wxyz);
  // (at most 64 axes and 64 buttons are kept: a client cannot make it allocate more)
  void receivedJoy(std::size_t robot, double stamp, const float* axes, std::size_t axis_count, const int* buttons,
                   std::size_t button_count);
  // (at most kMaxJoints joints, each name at most 256 characters, are kept)
  void receivedJointCommand(std::size_t robot, const char* const* names, std::size_t name_count, const double* positions,
                            std::size_t position_count, const double* velocities, std::size_t velocity_count);
  static constexpr std::size_t kMaxJoints = 64;

 private:
  // a message of `kind` whose values are `values`, staged (returned to set what else it carries)
  Outgoing& stageValues(Outgoing::Kind kind, std::size_t robot, double time, const std::vector<double>& values);
  void publishLoop();
  std::vector<std::string> missingSetpoints(double time) const;  // (mutex_ held)

  std::vector<RobotTopics> robots_;
  // what arrived
  mutable std::mutex mutex_;
  mutable std::condition_variable arrived_;
  std::vector<Setpoint> setpoints_;                                    // mutex_
  std::vector<Velocity> velocities_;                                   // mutex_
  std::vector<Joy> joys_;                                              // mutex_
  std::vector<JointCommand> joint_commands_;                           // mutex_
  std::vector<PoseSample> poses_;                                      // mutex_: not yet taken
  std::vector<std::size_t> queued_;                                    // mutex_: poses_ per robot
  std::vector<double> newest_pose_;                                    // mutex_: per robot (-1: none)
  std::uint64_t poses_dropped_ = 0;                                    // mutex_
  std::map<std::int64_t, std::chrono::steady_clock::time_point> sent_;  // odometry time (ns) -> wall time; mutex_
  std::vector<double> round_trips_;                                    // mutex_
  std::uint64_t received_ = 0;                                         // mutex_
  std::atomic<std::uint64_t> received_count_{0};                       // received_, published after each arrival
  // what goes out
  std::mutex queue_mutex_;
  std::condition_variable queue_changed_;
  std::vector<Outgoing> staged_;           // the stepping thread's, until commit hands them over
  std::vector<Outgoing> queue_, sending_;  // queue_mutex_ guards queue_, busy_, stop_
  std::vector<std::array<double, 3>> staged_points_, queue_points_, sending_points_;  // ranges', likewise
  std::vector<std::uint8_t> staged_bytes_, queue_bytes_, sending_bytes_;               // images', likewise
  std::vector<double> staged_values_, queue_values_, sending_values_;  // transforms' and joint states', likewise
  bool busy_ = false, stop_ = false;
  std::thread publisher_;
};

}  // namespace ssx::bridge
