// ros1: a SimulationExtension that bridges robots to ROS 1, so that real control programs talk to
// simulated robots (the paper's main use of extensions).
//
// Per robot (its artifact name is the namespace): /<name>/odom (nav_msgs/Odometry, world frame
// pose, body-frame twist), /<name>/imu (sensor_msgs/Imu) when it has an IMU sensor, a subscription
// to /<name>/setpoint (geometry_msgs/PoseStamped) that feeds its driver's external set-point
// (drivers implementing ssx::SetpointInterface, such as the quadrotor), and one to /<name>/cmd_vel
// (geometry_msgs/Twist, the robot's frame) for drivers that take velocity commands; /clock carries
// simulated time. Stamps are simulated time.
//
// The node is started in init (no SIGINT handler of its own: the host keeps Ctrl-C) with an
// asynchronous spinner; what arrived is applied in beforeStep, on the stepping thread. Messages are
// serialised and published on a thread of the bridge's own: a step only copies their numbers. With
// lockstep="true", after each odometry message the simulation waits (at most lockstep_timeout_s)
// until every robot has a set-point stamped at or after that odometry's time, so a controller
// outside sees the same timing in real time and in faster runs. All of that is the bridges' shared
// logic (plugins/bridge); this file is the ROS 1 transport's parameters.
//
// Parameters: kParameters below, or `ssx plugins --params ros1`.
#include "ros_bridge.hpp"

#include "../bridge/extension.hpp"

#include <cstdlib>

namespace ssx::plugins {

inline constexpr ssx_plugin_param kRos1Parameters[] = {
    param::text("master_uri", "", "ROS master (default: $ROS_MASTER_URI, else http://127.0.0.1:11311)"),
    param::text("node_name", "ssx", "name of the ROS node"),
    param::real("timeout_s", "5", "s", param::positive() & param::atMost(86400), "how long to wait for the master at start"),
};

class Ros1Bridge final : public bridge::BridgeExtension {
 public:
  static constexpr const char* kDoc =
      "bridges robots to ROS 1: odometry, IMU and /clock out, set-points and velocity commands in";
  static constexpr auto kParameters =
      param::join(param::part("ROS 1", kRos1Parameters), param::part("bridge", bridge::kBridgeParameters));

 protected:
  std::unique_ptr<bridge::Transport> open(Environment&, const Descriptor& params,
                                          const std::vector<bridge::RobotTopics>& robots) override {
    const char* env_uri = std::getenv("ROS_MASTER_URI");
    const std::string master =
        params.get<std::string>("master_uri", env_uri != nullptr ? env_uri : "http://127.0.0.1:11311");
    return ros1::open(master, params.get<std::string>("node_name"), params.get<double>("timeout_s"), robots);
  }
  void close(bridge::Transport& transport) override { ros1::close(transport); }
  const char* name() const override { return "ros1"; }
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_EXTENSION(ssx::plugins::Ros1Bridge, "ros1"));
