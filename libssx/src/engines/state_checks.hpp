#pragma once
// Whether a body state or a command is finite: the guards of the snapshot and drivers phases.

#include <ssx/physic_engine.hpp>
#include <ssx/physic_node.hpp>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <span>

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

/// Why a body's state read back from a saved state is not one an engine could have produced, in
/// the parts every engine keeps: a NaN or infinite value (of all its `values`), a position more
/// than 1e9 m from the origin, speeds beyond the guards; null when none. (Anything else could make
/// the engine fail inside its step, where it cannot be recovered.) The engine checks its rotation.
inline const char* savedBodyProblem(std::span<const double> values, const Vec3& position, const Vec3& linear,
                                    const Vec3& angular, const PhysicsSettings& physics) {
  for (const double v : values)
    if (!std::isfinite(v)) return "has a NaN or infinite value";
  if (position.cwiseAbs().maxCoeff() > 1e9) return "is more than 1e9 m from the origin";
  if (linear.norm() > physics.max_linear_speed || angular.norm() > physics.max_angular_speed)
    return "is faster than max_linear_speed or max_angular_speed";
  return nullptr;
}

}  // namespace ssx::detail
