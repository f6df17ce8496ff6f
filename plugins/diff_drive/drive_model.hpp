#pragma once
// The differential drive's dynamics: two driven wheels on one axle, in one of two models behind the
// same wheel commands and odometry:
//   full:  the wheels are bodies on hinge motors (the artifact's `left_wheel` and `right_wheel`
//          nodes, or several a side for a skid-steered robot such as the Husky); they roll on the
//          ground with its friction, so they can slip; the encoders read the hinges (a side's mean).
//   swarm: the robot is one body, driven each step to the twist its wheels would give by a force
//          and a torque of at most `max_force` and `max_torque` (as ARGoS's 2D dynamics drives a
//          foot-bot), held on its plane (its height and upright) by the same means; it touches
//          other bodies in 3D but not the floor, so it is cheap; the encoders read the wheels the
//          body's motion would turn.
// It knows nothing of who chooses the wheel speeds (ground_controller.hpp). Parameters:
// kDriveModelParameters.
#include <ssx/ssx.hpp>

#include <vector>

namespace ssx::ground {

inline constexpr ssx_plugin_param kDriveModelParameters[] = {
    param::choice("model", "swarm", "swarm full",
                  "full: wheel bodies on hinge motors, rolling with friction; swarm: one body driven to the wheels' "
                  "twist with limited force and torque"),
    param::required(param::real("wheel_radius", "", "m", param::positive() & param::atMost(10), "wheel radius")),
    param::required(param::real("axle_length", "", "m", param::positive() & param::atMost(100),
                                "distance between the two wheels' contact points")),
    param::required(param::real("max_wheel_speed", "", "rad/s", param::positive() & param::atMost(1e4),
                                "the fastest a wheel turns, either way")),
    param::text("left_wheel", "",
                "full model: the left wheel's node (a hinge with a motor; positive turns it forward), or the "
                "left side's wheel nodes separated by spaces (a skid-steered robot: all driven alike, the "
                "encoder their mean)"),
    param::text("right_wheel", "", "full model: the right wheel's node, or the right side's nodes"),
    param::real("max_force", "0", "N", param::nonNegative(),
                "swarm model: the largest force driving the body to the wheels' velocity; 0: friction times weight"),
    param::real("max_torque", "0", "N m", param::nonNegative(),
                "swarm model: the largest torque driving its yaw rate; 0: max_force times half the axle length"),
    param::real("encoder_noise", "0", "rad/s", param::nonNegative(),
                "standard deviation of each wheel speed the encoders measure, per driver step"),
};

/// The heading (yaw about +z) of an orientation.
double yawOf(const Quat& q);
/// An angle wrapped to (-pi, pi].
double wrapAngle(double a);

class DriveModel {
 public:
  /// The artifact's checks (a dynamic root; the full model's wheel nodes); throws ConfigError.
  static void validate(const Descriptor& params, const Artifact& a);
  /// Reads the parameters for artifact `a` (as it is placed: its height is kept, swarm model).
  void configure(const Descriptor& params, Artifact& a);

  /// Wheel speeds (rad/s), within max_wheel_speed: both scaled alike, so that the path's
  /// curvature is kept.
  void setWheels(double left, double right);
  /// The wheel speeds that give forward speed `v` (m/s) and yaw rate `w` (rad/s).
  void setTwist(double v, double w) { setWheels((v - w * axle_ / 2) / radius_, (v + w * axle_ / 2) / radius_); }
  double left() const { return left_cmd_; }
  double right() const { return right_cmd_; }

  /// Drives the robot at the commanded wheel speeds for a step of dt s (before the physics).
  void apply(double dt);
  /// The encoders after dt s (with their noise from `random`), and the pose dead-reckoned from them.
  void measure(double dt, Random& random);
  const Odometry& odometry() const { return odometry_; }

  double wheelRadius() const { return radius_; }
  double axleLength() const { return axle_; }
  double maxWheelSpeed() const { return max_wheel_; }

  void saveState(StateWriter& out) const;
  void loadState(StateReader& in);

 private:
  void drive(double dt);  // the swarm model

  Artifact* artifact_ = nullptr;
  bool full_ = false;
  double radius_ = 0, axle_ = 0, max_wheel_ = 0, noise_ = 0, mass_ = 0, max_force_ = 0, max_torque_ = 0, height_ = 0;
  Mat3 inertia_ = Mat3::Identity();
  Vec3 gravity_ = Vec3::Zero();
  std::vector<PhysicNode*> left_;  // the full model's wheels, each side's
  std::vector<PhysicNode*> right_;
  double left_cmd_ = 0, right_cmd_ = 0;
  Odometry odometry_;
};

}  // namespace ssx::ground
