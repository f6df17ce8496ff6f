#pragma once
/// @file
/// A way for bridges, programs and tests to command a vehicle's driver without knowing its class:
/// drivers that follow set-points implement SetpointInterface, and anyone finds it with
/// `dynamic_cast<ssx::SetpointInterface*>(artifact.driver())` (the type lives in libssx, so the
/// cast works across plugin libraries).

#include <ssx/export.hpp>
#include <ssx/types.hpp>

namespace ssx {

/// A reference for a vehicle: position, its derivatives for feed-forward, and heading.
struct Setpoint {
  Vec3 position = Vec3::Zero();      ///< m, world frame
  Vec3 velocity = Vec3::Zero();      ///< m/s, feed-forward
  Vec3 acceleration = Vec3::Zero();  ///< m/s^2, feed-forward
  double yaw = 0.0;                  ///< rad
  double yaw_rate = 0.0;             ///< rad/s, feed-forward
};

/// Implemented by drivers that track set-points. Call only between steps, or from an extension's
/// hooks, never from another artifact's driver or sensor (the parallel phases).
class SSX_EXPORT SetpointInterface {
 public:
  virtual ~SetpointInterface();
  /// Switches the driver to this external set-point (held until the next call).
  virtual void setSetpoint(const Setpoint& setpoint) = 0;
  /// The reference the driver tracks right now (from whatever source it uses).
  virtual Setpoint currentSetpoint() const = 0;
};

}  // namespace ssx
