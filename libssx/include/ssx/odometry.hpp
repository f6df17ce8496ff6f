#pragma once
/// @file
/// Wheel odometry of a ground robot: what its encoders measured and the pose dead-reckoned from
/// them. Drivers of wheeled robots (diff_drive) implement OdometryInterface; anyone finds it with
/// `dynamic_cast<ssx::OdometryInterface*>(artifact.driver())`.

#include <ssx/export.hpp>
#include <ssx/types.hpp>

namespace ssx {

/// A differential drive's odometry, in the frame it started in (x forward, y left, z up).
struct Odometry {
  double x = 0;            ///< m, dead-reckoned from the encoders
  double y = 0;            ///< m
  double yaw = 0;          ///< rad, in (-pi, pi]
  double forward = 0;      ///< m/s, from the encoders
  double yaw_rate = 0;     ///< rad/s, from the encoders
  double left_speed = 0;   ///< rad/s, the left wheel's measured speed
  double right_speed = 0;  ///< rad/s, the right wheel's measured speed
  double left_angle = 0;   ///< rad, the left wheel's turns since the start, measured
  double right_angle = 0;  ///< rad
};

/// Implemented by drivers that dead-reckon from wheel encoders. Read between steps, or from an
/// extension's hooks.
class SSX_EXPORT OdometryInterface {
 public:
  virtual ~OdometryInterface();
  /// The latest odometry (updated each time the driver runs).
  virtual Odometry odometry() const = 0;
};

}  // namespace ssx
