// ros2: a SimulationExtension that bridges robots to ROS 2 over DDS (Eclipse Cyclone DDS, the
// middleware of rmw_cyclonedds_cpp), without ROS 2 installed: it publishes and subscribes ROS 2's
// topics with ROS 2's types and QoS, so ROS 2 nodes see and drive the robots.
//
// Per robot (its artifact name is the namespace): /<name>/odom (nav_msgs/msg/Odometry, world frame
// pose, body-frame twist; default QoS), /<name>/imu (sensor_msgs/msg/Imu, sensor-data QoS) when it
// has an IMU sensor, /<name>/setpoint (geometry_msgs/msg/PoseStamped) in for drivers that follow
// set-points, /<name>/cmd_vel (geometry_msgs/msg/Twist, the robot's frame) in for drivers that take
// velocity commands; /clock (rosgraph_msgs/msg/Clock, clock QoS) carries simulated time. With the
// odometry, /tf (tf2_msgs/msg/TFMessage, tf2's QoS): each robot's <name>/base_link and its other
// bodies' frames <name>/<node> in the world frame, and /<name>/joint_states (sensor_msgs/msg/JointState)
// for a robot with hinges or sliders, each named by the node it moves; once, kept for later readers,
// /tf_static (every frame fixed in a body) and /<name>/robot_description (std_msgs/msg/String: a
// URDF written from the artifact, robot_description.hpp). With services="true" (the default), the
// ROS 2 standard simulation services (simulation_interfaces: /get_entities, /get_entity_state,
// /set_entity_state, /set_simulation_state, /step_simulation, /reset_simulation, ...;
// sim_services.hpp), answered between steps. Stamps are
// simulated time. What is published when, lock-step and applying what arrived between steps are the
// bridges' shared logic (plugins/bridge), as in the ros1 extension; this file is the DDS transport's
// parameters.
//
// Parameters: kParameters below, or `ssx plugins --params ros2`.
#include "dds_bridge.hpp"
#include "robot_description.hpp"
#include "sim_services.hpp"

#include "../bridge/extension.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>

namespace ssx::plugins {

inline constexpr ssx_plugin_param kRos2Parameters[] = {
    param::text("domain_id", "", "the ROS 2 domain, 0 to 232 (default: $ROS_DOMAIN_ID, else 0)"),
    param::choice("network", "loopback", "loopback system",
                  "loopback: this machine only (127.0.0.1; discovery by unicast there: a ROS 2 program uses the same "
                  "CYCLONEDDS_URI, see docs); system: Cyclone's choice of interfaces, or $CYCLONEDDS_URI's"),
    param::text("node_name", "ssx", "the ROS 2 node the bridge is to ROS tools (ros2 node list): letters, digits, _"),
    param::text("ros_distro", "",
                "the ROS 2 distribution of the tools that are to list the node (ros_discovery_info's layout: humble, "
                "galactic, foxy: Humble's; iron, jazzy, kilted, rolling and later: Iron's; default: $ROS_DISTRO, else jazzy)"),
    param::flag("services", "true",
                "serve ROS 2's simulation_interfaces services (/get_entities, /set_entity_state, /step_simulation, "
                "/reset_simulation, ...), answered between steps"),
};

class Ros2Bridge final : public bridge::BridgeExtension {
 public:
  static constexpr const char* kDoc =
      "bridges robots to ROS 2 over DDS: odometry, IMU, /tf, joint states, descriptions and /clock out, set-points "
      "and velocity commands in, the simulation_interfaces services";
  static constexpr auto kParameters =
      param::join(param::part("ROS 2", kRos2Parameters), param::part("bridge", bridge::kBridgeParameters));

  static void validate(const Descriptor& params, const PluginContext& context) {
    BridgeExtension::validate(params, context);
    (void)domainOf(params);
    const std::string node = params.get<std::string>("node_name");
    const bool valid = !node.empty() && node.size() <= 255 && !std::isdigit(static_cast<unsigned char>(node[0])) &&
                       std::all_of(node.begin(), node.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
    if (!valid)
      throw params.errorAt("node_name", "node_name '" + node + "' is not a ROS 2 node name: letters, digits and _, "
                                        "not starting with a digit");
    (void)distroOf(params);
  }

  void init(Environment& env, const Descriptor& params) override {
    BridgeExtension::init(env, params);
    try {
      if (params.get<bool>("services"))
        services_ = std::make_unique<ros2::SimulationServices>(ros2::participant(*dds_), env, "",
                                                               [this] { restarted(); });
      // (last: it lists every reader and writer made)
      ros2::announce(*dds_, params.get<std::string>("node_name"), distroOf(params));
    } catch (const std::exception& e) {
      services_.reset();
      BridgeExtension::shutdown(env);
      throw params.error(e.what());
    }
  }
  void afterStep(Environment& env) override {
    BridgeExtension::afterStep(env);
    if (services_) services_->afterStep();
  }
  void shutdown(Environment& env) override {
    if (services_) {
      if (const std::string line = services_->summary(); !line.empty()) env.log(LogLevel::Info, line);
      services_.reset();  // (before the participant its endpoints belong to)
    }
    BridgeExtension::shutdown(env);
  }

 protected:
  std::unique_ptr<bridge::Transport> open(Environment&, const Descriptor& params,
                                          const std::vector<bridge::RobotTopics>& robots) override {
    const auto network = params.get<std::string>("network") == "system" ? ros2::Network::System : ros2::Network::Loopback;
    auto t = ros2::open(domainOf(params), network, robots, params.get<bool>("lockstep"));
    dds_ = t.get();
    return t;
  }
  void close(bridge::Transport& transport) override { ros2::close(transport); }
  const char* name() const override { return "ros2"; }
  bool offersTransforms() const override { return true; }
  std::string describe(const Artifact& a) const override { return ros2::robotDescription(a); }

 private:
  bridge::Transport* dds_ = nullptr;  // the transport open() made (the base owns it)
  std::unique_ptr<ros2::SimulationServices> services_;
  // the parameter, else $ROS_DISTRO, else jazzy: a distribution's name (lower-case letters; one ssx does
  // not know yet is taken to be as Iron's and later ones)
  static std::string distroOf(const Descriptor& params) {
    const char* from_env = std::getenv("ROS_DISTRO");
    std::string distro = params.get<std::string>("ros_distro", "");
    if (distro.empty()) distro = from_env != nullptr && *from_env != '\0' ? from_env : "jazzy";
    const bool valid = distro.size() <= 32 && std::all_of(distro.begin(), distro.end(), [](char c) { return c >= 'a' && c <= 'z'; });
    if (!valid) {
      const std::string what = "'" + distro + "' is not a ROS 2 distribution's name (humble, jazzy, ...)";
      if (!params.get<std::string>("ros_distro", "").empty()) throw params.errorAt("ros_distro", "ros_distro " + what);
      throw params.error("ROS_DISTRO " + what + ": give ros_distro");
    }
    return distro;
  }
  // the parameter, else $ROS_DOMAIN_ID, else 0; a domain ROS 2 cannot use is an error where it was given
  static int domainOf(const Descriptor& params) {
    const char* from_env = std::getenv("ROS_DOMAIN_ID");
    const std::string text = params.get<std::string>("domain_id", from_env != nullptr ? from_env : "0");
    int domain = -1;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), domain);
    if (ec != std::errc() || end != text.data() + text.size() || domain < 0 || domain > 232) {
      const std::string where = params.has("domain_id") ? "" : " ($ROS_DOMAIN_ID)";
      if (params.has("domain_id"))
        throw params.errorAt("domain_id", "domain_id '" + text + "' is not a ROS 2 domain: give 0 to 232");
      throw params.error("ROS_DOMAIN_ID is '" + text + "', not a ROS 2 domain: give 0 to 232, or domain_id" + where);
    }
    return domain;
  }
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_EXTENSION(ssx::plugins::Ros2Bridge, "ros2"));
