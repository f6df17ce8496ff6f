#pragma once
// The ROS 1 side of the ros1 extension: everything that touches roscpp, compiled as C++17 (ROS's
// message headers do not compile as C++20). This header uses only the standard library and the
// bridges' shared transport (plugins/bridge/transport.hpp), so the C++20 plugin code can include it.

#include "../bridge/transport.hpp"

#include <memory>
#include <string>
#include <vector>

namespace ssx::ros1 {

// Starts a ROS node (no SIGINT handler of its own) with an asynchronous spinner, advertising and
// subscribing the robots' topics; throws std::runtime_error when no master answers at `master_uri`
// within `timeout_s`, or when a node already runs in this process.
std::unique_ptr<bridge::Transport> open(const std::string& master_uri, const std::string& node_name, double timeout_s,
                                        const std::vector<bridge::RobotTopics>& robots);
// Sends what is staged, then stops the publishing thread, the spinner and the node.
void close(bridge::Transport& transport);

}  // namespace ssx::ros1
