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

// a sensor's frame name (without the robot's prefix): `base` ("imu", "scan", "camera"), or
// `base`_sensor when one of the robot's own links has that name already (a URDF's camera link)
inline std::string sensorFrame(const Artifact& a, const std::string& base) {
  for (std::size_t k = 0; k < a.nodeCount(); ++k)
    if (linkName(a, a.nodeAt(k)) == base) return base + "_sensor";
  return base;
}

// `child` at `pose` in the link of `node`, on /tf_static
inline void fixedIn(const Artifact& a, const PhysicNode& node, const std::string& child, const Pose& pose,
                    RobotTopics& t) {
  StaticFrame f;
  f.parent = a.name() + "/" + linkName(a, node);
  f.child = a.name() + "/" + child;
  const Quat& q = pose.orientation;
  f.pose = {pose.position.x(), pose.position.y(), pose.position.z(), q.w(), q.x(), q.y(), q.z()};
  t.statics.push_back(f);
}

// The frames of a robot's sensors on /tf_static, so that tf2 resolves every message's frame_id:
// the IMU (sensor `imu`: what it measures is in its node's frame) at its node; the proximity ring
// (sensor `ring`) at its node raised by the rays' height, where the scan's rays start; the camera
// (sensor `camera`) at its mount, looking along x, and its optical frame (z forward, x right, y
// down: REP 103's camera convention, what image_geometry and depth projection expect), the frame
// of its images and camera_info. A sensor index past the robot's sensors: none.
inline void sensorFrames(const Artifact& a, std::size_t imu, std::size_t ring, std::size_t camera, RobotTopics& t) {
  if (imu < a.sensorCount()) {
    t.imu_frame = sensorFrame(a, "imu");
    fixedIn(a, a.nodeFromParameter(a.sensorParameters(imu)), t.imu_frame, Pose{}, t);
  }
  if (ring < a.sensorCount() && t.scan) {
    const Descriptor& params = a.sensorParameters(ring);
    t.scan_frame = sensorFrame(a, "scan");
    fixedIn(a, a.nodeFromParameter(params), t.scan_frame, Pose{Vec3(0, 0, params.get<double>("height", 0.0)), Quat::Identity()}, t);
  }
  if (camera < a.sensorCount() && t.image) {
    const Descriptor& params = a.sensorParameters(camera);
    // (the mount as the camera sensor reads it: roll, pitch, yaw about fixed axes)
    const Vec3 rpy = params.get<Vec3>("rpy", Vec3::Zero());
    const Pose mount{params.get<Vec3>("xyz", Vec3::Zero()),
                     Quat(Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))};
    const std::string body = sensorFrame(a, "camera");
    fixedIn(a, a.nodeFromParameter(params), body, mount, t);
    // the optical frame's axes in the camera's: x right (-y), y down (-z), z forward (+x)
    Eigen::Matrix3d optical;
    optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    t.camera_frame = sensorFrame(a, "camera_optical");
    StaticFrame f;
    f.parent = a.name() + "/" + body;
    f.child = a.name() + "/" + t.camera_frame;
    const Quat q(optical);
    f.pose = {0, 0, 0, q.w(), q.x(), q.y(), q.z()};
    t.statics.push_back(f);
  }
}

// a proximity ring on /<name>/scan (the rays, their reach and the ring's radius come with each
// scan: the sensor knows them once configured), in the frame sensorFrames gives it
inline void scanOf(RobotTopics& t) {
  t.scan = true;
  t.scan_frame = "scan";
}

}  // namespace ssx::bridge
