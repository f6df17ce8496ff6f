#pragma once
// The names of a robot's frames on /tf and of the links of its description (plugins/ros2): its
// root "base_link" (its own name when another of its nodes is named so: a URDF's base_footprint
// above its base_link), every other physic node by its name ("node_K", K its index in the
// artifact, for a node without one), prefixed by the robot's name on /tf ("q0/base_link",
// "q0/left_wheel").
#include <ssx/artifact.hpp>

#include <string>

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

}  // namespace ssx::bridge
