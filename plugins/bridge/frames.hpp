#pragma once
// The names of a robot's frames on /tf and of the links of its description (plugins/ros2): its
// root "base_link" (its own name when another of its nodes is named so: a URDF's base_footprint
// above its base_link), every other physic node by its name ("node_K", K its index in the
// artifact, for a node without one), prefixed by the robot's name on /tf ("q0/base_link",
// "q0/left_wheel"); which of them are on /tf, /tf_static and joint_states (frames()).
#include "transport.hpp"

#include <ssx/artifact.hpp>
#include <ssx/measurements.hpp>

#include <string>
#include <vector>

namespace ssx::bridge {

/// A node's link name, without the robot's prefix.
inline std::string linkName(const Artifact& a, const PhysicNode& node) {
  if (&node == &a.root()) {
    for (std::size_t k = 0; k < a.nodeCount(); ++k)
      if (&a.nodeAt(k) != &node && a.nodeAt(k).name() == "base_link") return node.name().empty() ? "root" : node.name();
    return "base_link";
  }
  if (!node.name().empty()) return node.name();
  for (std::size_t k = 0; k < a.nodeCount(); ++k)
    if (&a.nodeAt(k) == &node) return "node_" + std::to_string(k);
  return "node";
}

// a robot's frames: its other bodies (a joined part, another root) on /tf, each hinge and slider
// among them on joint_states, every other node on /tf_static in its body's frame
inline void frames(const Artifact& a, std::vector<const PhysicNode*>& parts, std::vector<const PhysicNode*>& joints,
                   RobotTopics& t) {
  const auto isPart = [&a](const PhysicNode& n) {
    const bool another_root = n.parent() == nullptr && &n != &a.root() && !n.isStatic();
    return another_root || n.joint().isBody();
  };
  const std::string prefix = a.name() + "/";
  for (std::size_t k = 0; k < a.nodeCount(); ++k) {
    const PhysicNode& n = a.nodeAt(k);
    if (&n == &a.root() || n.isStatic()) continue;
    if (isPart(n)) {
      parts.push_back(&n);
      t.parts.push_back(linkName(a, n));
      if (n.joint().hasPosition()) {
        joints.push_back(&n);
        t.joints.push_back(linkName(a, n));
      }
      continue;
    }
    // fixed in its body: its pose in the frame of the node that body begins at
    Pose in_head = n.spec().pose;
    const PhysicNode* head = n.parent();
    while (head != nullptr && head != &a.root() && !isPart(*head)) {
      in_head = head->spec().pose * in_head;
      head = head->parent();
    }
    if (head == nullptr) continue;
    StaticFrame f;
    f.parent = prefix + linkName(a, *head);
    f.child = prefix + linkName(a, n);
    const Quat& q = in_head.orientation;
    f.pose = {in_head.position.x(), in_head.position.y(), in_head.position.z(), q.w(), q.x(), q.y(), q.z()};
    t.statics.push_back(f);
  }
}

// a proximity ring on /<name>/scan, in the robot's base frame (the rays, their reach and the ring's
// radius come with each scan: the sensor knows them once configured)
inline void scanOf(const Artifact& a, RobotTopics& t) {
  t.scan = true;
  t.scan_frame = linkName(a, a.root());
}

}  // namespace ssx::bridge
