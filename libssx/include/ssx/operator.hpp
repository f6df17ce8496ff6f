#pragma once
/// @file
/// Operators: people steering robots by velocity (a joystick, a haptic device, the viewer's keys)
/// and feeling the world they steer them through. The `operator` extension implements it; the
/// bridges, Python and the embedding program find it with
/// `dynamic_cast<ssx::OperatorInterface*>(env.extension(name))` (the type lives in libssx, so the
/// cast works across plugin libraries).

#include <ssx/export.hpp>
#include <ssx/types.hpp>

#include <span>
#include <vector>

namespace ssx {

class Artifact;

/// One operator: the robots it steers as one, its commands in, the force to render out.
class SSX_EXPORT OperatorInterface {
 public:
  virtual ~OperatorInterface();
  /// Steers every robot of the operator with this velocity (m/s) and yaw rate (rad/s), in the
  /// operator's frame, clipped to its limits; held until the next command, or until the dead-man
  /// rule stops the robots. Between steps. Error for a value that is not finite.
  virtual void command(const Vec3& velocity, double yaw_rate) = 0;
  /// A joystick's state (sensor_msgs/Joy): the axes it maps to velocity and yaw rate (scaled by
  /// the limits), its dead-man button (released: the robots stop). Between steps.
  virtual void joy(std::span<const float> axes, std::span<const int> buttons) = 0;
  /// The force to render on the operator's device now (N, world frame), by the documented law.
  virtual Vec3 force() const = 0;
  /// How often the force is worth sending, Hz of simulated time (0: every step).
  virtual double forceRateHz() const = 0;
  /// The robots it steers.
  virtual const std::vector<Artifact*>& steered() const = 0;
};

}  // namespace ssx
