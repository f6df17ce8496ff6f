#pragma once
// What the bridges do with a command that arrived, between steps: a set-point to a driver that
// follows them, a Twist turned into the world's frame for a driver that takes velocities, a joint
// command to the joints it names (all checked before any is set). Each throws ssx::Error saying why
// a command cannot be used; the bridge drops it and counts it.
#include "frames.hpp"
#include "transport.hpp"

#include <ssx/artifact.hpp>
#include <ssx/command.hpp>
#include <ssx/error.hpp>
#include <ssx/setpoint.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace ssx::bridge {

inline void applySetpoint(SetpointInterface& tracker, const Setpoint& s) {
  ssx::Setpoint sp;
  sp.position = Vec3(s.position[0], s.position[1], s.position[2]);
  const Quat q(s.orientation[0], s.orientation[1], s.orientation[2], s.orientation[3]);
  if (!q.coeffs().allFinite() || q.norm() < 1e-6) throw Error("its orientation is not a rotation (a zero or non-finite quaternion)");
  sp.yaw = std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()));
  Command c;
  c.level = CommandLevel::Position;
  c.setpoint = sp;
  if (const std::string why = c.problem(); !why.empty()) throw Error(why);
  tracker.setSetpoint(sp);
}

// a joint command: every joint it names to its position (or, without positions, its velocity),
// all checked before any is set
inline void applyJoints(const Artifact& artifact, const std::vector<const PhysicNode*>& joints, const JointCommand& j) {
  const bool by_position = !j.positions.empty();
  const std::vector<double>& values = by_position ? j.positions : j.velocities;
  if (values.size() != j.names.size())
    throw Error(std::to_string(j.names.size()) + " names with " + std::to_string(j.positions.size()) +
                " positions and " + std::to_string(j.velocities.size()) +
                " velocities (give one position, or one velocity, per name)");
  std::vector<PhysicNode*> nodes;
  for (std::size_t k = 0; k < j.names.size(); ++k) {
    PhysicNode* node = nullptr;
    for (const PhysicNode* n : joints)
      if (linkName(artifact, *n) == j.names[k]) node = const_cast<PhysicNode*>(n);
    if (node == nullptr) throw Error("no joint '" + j.names[k] + "' (its joints are named by the node each moves)");
    const JointSpec& spec = node->joint();
    if (!(spec.max_effort > 0)) throw Error("joint '" + j.names[k] + "' has no motor");
    if (!std::isfinite(values[k]) || (by_position && (values[k] < spec.lower || values[k] > spec.upper)))
      throw Error("joint '" + j.names[k] + "': " + std::to_string(values[k]) + " is not finite or outside its limits");
    nodes.push_back(node);
  }
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (by_position) nodes[k]->setJointPosition(values[k]);
    else nodes[k]->setJointVelocity(values[k]);
  }
}

// a Twist in the robot's frame (x forward): turned by its heading into the world's
inline void applyVelocity(const Artifact& artifact, CommandInterface& commands, const Velocity& v) {
  const Quat q = artifact.root().pose().orientation;
  const double yaw = std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()));
  const Vec3 world(std::cos(yaw) * v.linear[0] - std::sin(yaw) * v.linear[1],
                   std::sin(yaw) * v.linear[0] + std::cos(yaw) * v.linear[1], v.linear[2]);
  const Command c = Command::velocityYawRate(world, v.angular[2]);
  // (checked before it is turned: an absurd speed overflows in the turn)
  const Command raw = Command::velocityYawRate(Vec3(v.linear[0], v.linear[1], v.linear[2]), v.angular[2]);
  if (const std::string why = raw.problem(); !why.empty()) throw Error(why);
  if (const std::string why = commands.refusal(c); !why.empty()) throw Error(why);
  commands.setCommand(c);
}

}  // namespace ssx::bridge
