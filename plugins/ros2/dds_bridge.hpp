#pragma once
// The ROS 2 side of the ros2 extension: the bridges' transport (plugins/bridge/transport.hpp) over
// Eclipse Cyclone DDS, speaking ROS 2's topics as ROS 2 maps them onto DDS: the topic /a/b is the
// DDS topic rt/a/b, the message pkg/msg/T the DDS type pkg::msg::dds_::T_ in plain CDR (XCDR1),
// the QoS as rclcpp's profiles (idl/ros2_messages.idl holds the types).
#include "../bridge/transport.hpp"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace ssx::ros2 {

/// Where the DDS participant talks.
enum class Network {
  Loopback,  ///< 127.0.0.1 only, discovery by unicast to the well-known ports there (the default)
  System,    ///< Cyclone's own choice of interfaces, or $CYCLONEDDS_URI's
};

/// The Cyclone DDS configuration of Network::Loopback (a ROS 2 program on this machine that is to
/// see ssx uses the same, in CYCLONEDDS_URI).
std::string loopbackConfig();

/// Joins DDS domain `domain`, creating its topics, writers and readers; throws std::runtime_error
/// saying why when DDS cannot start. A ghost's poses are read best-effort (a motion-capture driver's
/// sensor-data QoS matches), reliably when `reliable_poses` (lock-step: no pose may be lost).
std::unique_ptr<bridge::Transport> open(int domain, Network network, const std::vector<bridge::RobotTopics>& robots,
                                        bool reliable_poses);
/// Sends what is staged, then leaves the domain.
void close(bridge::Transport& transport);
/// The transport's DDS participant (for the services on the same node), 0 once closed.
int participant(const bridge::Transport& transport);
/// An error naming what failed and Cyclone's return code.
std::runtime_error ddsError(const std::string& what, int code);
/// Tells ROS 2's graph (ros_discovery_info) that the participant is the node /`node`, with every
/// reader and writer it has now; kept for ROS tools that start later. `distro` is the ROS 2
/// distribution of the tools (humbleDiscovery: which layout). Throws std::runtime_error.
void announce(const bridge::Transport& transport, const std::string& node, const std::string& distro);
/// Whether ROS 2 `distro`'s tools read ros_discovery_info in Humble's layout (24-byte ids: Foxy,
/// Galactic, Humble) rather than Iron's and later ones' (16 bytes).
bool humbleDiscovery(const std::string& distro);

}  // namespace ssx::ros2
