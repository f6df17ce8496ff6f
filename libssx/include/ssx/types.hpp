#pragma once
/// @file
/// Basic value types: vectors, rotations, poses, time.

#include <ssx/export.hpp>

#include <Eigen/Geometry>

#include <cstdint>
#include <stdexcept>
#include <string>

namespace ssx {

using Vec3 = Eigen::Vector3d;     ///< a 3-vector (positions in m, velocities, forces), Eigen's
using Mat3 = Eigen::Matrix3d;     ///< a 3x3 matrix (inertia tensors), Eigen's
using Quat = Eigen::Quaterniond;  ///< a unit quaternion (orientations), Eigen's

/// Simulation time and durations, in integer nanoseconds: time is a step count times the
/// timestep, so it never drifts.
using Nanoseconds = std::int64_t;

/// Seconds (floating point) to integer nanoseconds, rounded to the nearest nanosecond. Throws
/// std::out_of_range for NaN and for more than 9.2e9 s (292 years) either way, which would not fit.
constexpr Nanoseconds toNanoseconds(double seconds) {
  if (!(seconds > -9.2e9 && seconds < 9.2e9))
    throw std::out_of_range("a time of " + std::to_string(seconds) + " s does not fit in 64-bit nanoseconds");
  return static_cast<Nanoseconds>(seconds * 1e9 + (seconds >= 0 ? 0.5 : -0.5));
}
/// Integer nanoseconds to seconds.
constexpr double toSeconds(Nanoseconds ns) { return static_cast<double>(ns) * 1e-9; }

/// A rigid transform. As the pose of a frame F in a frame W, it maps F-coordinates to W:
/// `p_W = orientation * p_F + position`.
struct Pose {
  Vec3 position = Vec3::Zero();         ///< of F's origin in W, m
  Quat orientation = Quat::Identity();  ///< of F's axes in W (unit)

  /// The identity transform.
  static Pose identity() { return {}; }
  /// Maps a point given in this frame into the parent frame.
  Vec3 transformPoint(const Vec3& p) const { return orientation * p + position; }
  /// Composition: `(a * b)` is b expressed in the frame a is expressed in.
  Pose operator*(const Pose& b) const {
    return {orientation * b.position + position, (orientation * b.orientation).normalized()};
  }
  /// The inverse transform.
  Pose inverse() const {
    const Quat q = orientation.conjugate();
    return {-(q * position), q};
  }
};

/// The rotation vector (axis times angle, rad, in the frame both are given in) that turns the
/// orientation `from` into `to`, the short way round.
inline Vec3 rotationBetween(const Quat& from, const Quat& to) {
  Quat d = to * from.conjugate();
  if (d.w() < 0) d.coeffs() = -d.coeffs();
  const Eigen::AngleAxisd aa(d);
  return aa.axis() * aa.angle();
}

/// The kinematic state of a rigid body or of a point fixed on it, all in the world frame.
/// Velocities and accelerations are those of the frame's origin.
struct SSX_EXPORT BodyState {
  Pose pose;                                 ///< the frame's pose in the world
  Vec3 linear_velocity = Vec3::Zero();       ///< m/s, world frame
  Vec3 angular_velocity = Vec3::Zero();      ///< rad/s, world frame
  Vec3 linear_acceleration = Vec3::Zero();   ///< m/s^2, world frame, gravity included
  Vec3 angular_acceleration = Vec3::Zero();  ///< rad/s^2, world frame

  /// The state of another frame rigidly attached to this one, given by its pose relative
  /// to this frame (rigid-body kinematics: v + w x r, a + alpha x r + w x (w x r)).
  BodyState attached(const Pose& relative) const;
};

/// Which frame a vector is expressed in.
enum class Frame : std::uint8_t {
  World,  ///< the world frame
  Local,  ///< the frame of the node being acted on
};

}  // namespace ssx
