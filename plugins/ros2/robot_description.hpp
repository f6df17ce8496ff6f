#pragma once
// A robot's description for ROS tools (/<robot>/robot_description, RViz's RobotModel): a URDF
// written from the artifact as ssx has it, whatever file it came from. Its links are the
// artifact's physic nodes, named as /tf names their frames (plugins/bridge/frames.hpp: the root
// base_link unless another node has that name); each link's visuals are the render trees that follow it (boxes, spheres, cylinders; a
// capsule as a cylinder and two spheres; a mesh by its file, with the scale it was read with);
// its joints are the nodes' joints (hinge: revolute within its limits, else continuous; slider:
// prismatic; ball: floating, as URDF has no ball joint; none: fixed), at each node's pose in its
// parent's. Names are the /tf frames without the robot's prefix (plugins/bridge/frames.hpp): with
// RViz's "TF Prefix" set to the robot's name, every link finds its frame.
#include <ssx/artifact.hpp>

#include <string>

namespace ssx::ros2 {

/// The URDF of artifact `a` (named after it).
std::string robotDescription(const Artifact& a);

}  // namespace ssx::ros2
