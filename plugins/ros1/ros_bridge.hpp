#pragma once
// The ROS 1 side of the ros1 extension: everything that touches roscpp, compiled as C++17 (ROS's
// message headers do not compile as C++20). This header uses only the standard library, so the
// C++20 plugin code can include it.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ssx::ros1 {

struct Odometry {
  double time = 0;  // simulated seconds
  std::array<double, 3> position{};                                  // world
  std::array<double, 3> velocity{}, angular_velocity{};              // body frame (ROS: child frame)
  std::array<double, 4> orientation{1, 0, 0, 0};                   // w x y z
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
};

struct RobotTopics {
  std::string name;  // namespace: /<name>/odom, /<name>/imu, /<name>/setpoint
  bool imu = false;
  bool setpoint = false;
};

class Bridge {
 public:
  // Starts a ROS node (no SIGINT handler of its own) and an asynchronous spinner; throws
  // std::runtime_error when no master answers at `master_uri` within `timeout_s`.
  Bridge(const std::string& master_uri, const std::string& node_name, double timeout_s,
         const std::vector<RobotTopics>& robots);
  ~Bridge();
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;

  // Queue a message for the bridge's publishing thread, which serialises and sends it: the caller
  // (the stepping thread) only copies a few numbers, taking no lock. commit() hands what is queued
  // to that thread (one lock and one wake-up per step, not per message). Messages go out in the
  // order queued, with the stamps given (simulated time).
  void publishClock(double time);
  void publishOdometry(std::size_t robot, const Odometry& odom);
  void publishImu(std::size_t robot, const Imu& imu);
  void commit();
  // Waits until everything queued so far has been handed to ROS.
  void flush();
  // The newest set-point of a robot (count 0: none yet). Thread-safe.
  Setpoint latestSetpoint(std::size_t robot) const;
  // Waits until every robot with a set-point topic has one stamped at or after `time` (seconds),
  // at most `timeout_s`; returns the names of those still missing (empty: all there).
  std::vector<std::string> waitForSetpoints(double time, double timeout_s) const;
  // Waits until every robot's odometry has a subscriber and its set-point topic a publisher (ROS
  // connects them asynchronously: a message sent before that is lost), at most `timeout_s`;
  // returns the names of the robots still unconnected.
  std::vector<std::string> waitForPeers(double timeout_s) const;
  // Round trips in wall-clock seconds: from publishing the odometry of time t to receiving a
  // set-point stamped t (one sample per set-point that answers an odometry message).
  std::vector<double> roundTrips() const;
  // Sends what is queued, then stops the publishing thread, the spinner and the node.
  void shutdown();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ssx::ros1
