#pragma once
// Whether a body state or a command is finite: the guards of the snapshot and drivers phases.

#include <ssx/physic_engine.hpp>
#include <ssx/physic_node.hpp>

#include <Eigen/Eigenvalues>

namespace ssx::detail {

inline bool finite(const BodyState& s) {
  return s.pose.position.allFinite() && s.pose.orientation.coeffs().allFinite() && s.linear_velocity.allFinite() &&
         s.angular_velocity.allFinite();
}

inline bool finite(const Wrench& w) { return w.force.allFinite() && w.torque.allFinite(); }

/// The largest force and torque (norms) a body may be commanded for one step.
struct WrenchLimit {
  double force = 0, torque = 0;
};

/// max_linear_speed * mass / step and max_angular_speed * (smallest principal moment) / step:
/// beyond them one step would take the body past the speed guards, and the engine could fail
/// inside its step (ODE asserts on the quaternions it then meets) instead of the run stopping
/// with a clear error.
inline WrenchLimit wrenchLimit(const MassProperties& mass, const PhysicsSettings& physics, Nanoseconds step) {
  const double dt = toSeconds(step);
  const double smallest = Eigen::SelfAdjointEigenSolver<Mat3>(mass.inertia, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
  return {physics.max_linear_speed * mass.mass / dt, physics.max_angular_speed * smallest / dt};
}

inline bool withinLimit(const Wrench& w, const WrenchLimit& limit) {
  return w.force.norm() <= limit.force && w.torque.norm() <= limit.torque;
}

}  // namespace ssx::detail
