#pragma once
// diff_drive: the driver of a differential-drive ground robot, assembled from parts that change for
// different reasons:
//   drive_model.hpp        the wheels and the body: full (wheel bodies on hinge motors) or swarm
//                          (one body driven to the wheels' twist); the encoders and odometry
//   ground_controller.hpp  the behaviour's interface; the driver holds at most one, chosen at load
//   behaviours.hpp         the built-in ones: diffusion, beeclust, foraging, twist
// Commands: `wheels` (left, right wheel speeds, rad/s) or `velocity` (the velocity's component
// along the heading, and the yaw rate), clamped to `max_wheel_speed` (a velocity command keeps its
// curvature); a command from outside takes over from the controller. Odometry:
// ssx::OdometryInterface, dead-reckoned from the encoders.
//
// A behaviour of one's own: derive a driver from DiffDrive, return the controller from
// makeController, and register it (SSX_DRIVER) in a plugin library linked with ssx::diff_drive.
//
// Parameters: kParameters (`ssx plugins --params diff_drive` prints them by part).
#include "../common/hold.hpp"
#include "behaviours.hpp"
#include "drive_model.hpp"
#include "ground_controller.hpp"

#include <ssx/ssx.hpp>

#include <memory>

namespace ssx::ground {

class DiffDrive : public Driver, public CommandInterface, public OdometryInterface {
 public:
  static constexpr const char* kDoc =
      "a differential-drive ground robot: wheels on hinge motors (full) or one body driven to the wheels' twist "
      "(swarm)";
  static constexpr auto kParameters =
      param::join(param::part("drive", kDriveModelParameters), param::part("controller", kBehaviourParameters),
                  param::part("hold", plugins::kHoldParameters));
  static void validate(const Descriptor& params, const PluginContext& context);

  void configure(const Descriptor& params, PluginSetup& setup) override;
  void step(const StepInfo& info) override;
  void saveState(StateWriter& out) const override;
  void loadState(StateReader& in) override;

  bool acceptsCommand(CommandLevel level) const override {
    return level == CommandLevel::Wheels || level == CommandLevel::Velocity;
  }
  std::size_t rotorCount() const override { return 0; }
  void setCommand(const Command& c) override;
  CommandLevel commandLevel() const override { return level_; }
  Command currentCommand() const override { return Command::wheels(drive_.left(), drive_.right()); }
  Setpoint currentSetpoint() const override;
  Odometry odometry() const override { return drive_.odometry(); }

  /// For tests and derived drivers: the parts.
  const DriveModel& drive() const { return drive_; }
  const GroundController* controller() const { return controller_.get(); }

 protected:
  /// The behaviour driving the robot (null: commands from outside only), made once at load, after
  /// the drive model is configured. This one makes the built-in behaviour `controller` names.
  virtual std::unique_ptr<GroundController> makeController(const Descriptor& params, const Artifact& a,
                                                           const DriveModel& drive) {
    return makeBehaviour(params, a, drive);
  }

 private:
  DriveModel drive_;
  std::unique_ptr<GroundController> controller_;
  bool active_ = false;  // the controller drives it (until a command from outside)
  CommandLevel level_ = CommandLevel::Wheels;
  plugins::Hold hold_;
};

}  // namespace ssx::ground
