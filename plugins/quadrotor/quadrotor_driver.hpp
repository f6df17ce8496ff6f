#pragma once
// quadrotor: the driver of a quadrotor, assembled from parts that change for different reasons:
//   vehicle.hpp             the rigid body, rotors and motors, battery
//   effects.hpp             wind (the scene's <wind> and the artifact's own), ground effect, downwash
//   controller.hpp          the flight controller's interface; the driver holds one, chosen at load:
//   telekyb_controller.hpp    TeleKyb's, taking commands at the five command levels (ssx/command.hpp)
//   crazyflie_pid.hpp         the Crazyflie firmware's (controller="crazyflie_pid")
//   references.hpp          hover, figure eights, formation, trajectory file, external set-points
//
// Parameters: each part's table, joined in kParameters (`ssx plugins --params quadrotor` prints
// them by part). The preset (presets/quadrotor/NAME.xml) gives every value the element does not.
//
// Timing: the driver runs every `period` steps and integrates its motors over that period; the
// controller's loops run every k of its runs (checked while loading).
//
// Needs a sensor producing ssx::ImuMeasurement on the artifact (the `imu` plugin). Uses the first
// sensor producing ssx::PoseMeasurement (a motion-capture stand-in) for position and velocity,
// else the ground truth. The formation needs a `range` sensor; its members must be one swarm
// (consecutive artifacts), member i at artifact index (own - own i + i).
#include "../common/hold.hpp"
#include "controller.hpp"
#include "crazyflie_pid.hpp"
#include "effects.hpp"
#include "references.hpp"
#include "telekyb_controller.hpp"
#include "vehicle.hpp"

#include <ssx/ssx.hpp>

#include <array>
#include <memory>
#include <optional>

namespace ssx::quadrotor {

class QuadrotorDriver final : public Driver,
                              public CommandInterface,
                              public MetricSource,
                              public VariationInterface,
                              private FlightInputs {
 public:
  static constexpr const char* kDoc =
      "vehicle (rotors, motors, battery), environment effects, TeleKyb controller (integer attitude loop on IMU "
      "counts, position loop; five command levels), references";
  static constexpr auto kParameters =
      param::join(param::part("vehicle", kVehicleParameters), param::part("ground effect", kGroundEffectParameters),
                  param::part("wind", kWindParameters), param::part("downwash", kDownwashParameters),
                  param::part("controller", kControllerChoiceParameters),
                  param::part("controller (TeleKyb)", kTeleKybParameters), param::part("references", kReferenceParameters),
                  param::part("hold", plugins::kHoldParameters));
  static void validate(const Descriptor& params, const PluginContext& context);
  void configure(const Descriptor& params, PluginSetup& setup) override;
  void step(const StepInfo& info) override;
  void saveState(StateWriter& out) const override;
  void loadState(StateReader& in) override;

  /// Every level (TeleKybController), position and velocity (crazyflie_pid); a position command
  /// is an external set-point.
  bool acceptsCommand(CommandLevel level) const override { return flight().accepts(level); }
  std::size_t rotorCount() const override { return vehicle_.rotorCount(); }
  void setCommand(const Command& command) override;
  CommandLevel commandLevel() const override { return flight().level(); }
  Command currentCommand() const override;
  Setpoint currentSetpoint() const override { return flight().currentSetpoint(); }
  /// In formation: `formation_error`, the mean over the members its range sensor sees whose
  /// places on the sphere are within sensing range of its own, of | distance - desired distance |
  /// (m), as of its latest range measurement (NaN when it sees none). Following a robot: `landed`,
  /// 1 once it came down on it and stopped its motors, else 0.
  std::vector<std::string> metricNames() const override;
  void metrics(std::vector<Metric>& out) const override;
  /// The rotors' and motors' constants (factors: the flight controller keeps the configured ones)
  /// and the mean wind (an offset, m/s), for domain randomisation (ssx/variation.hpp).
  std::span<const Variable> variables() const override;
  void vary(std::size_t k, double value) override;

  /// For tests: the parts.
  const RotorModel& rotors() const { return vehicle_.rotors(); }
  /// The flight controller, chosen at load: TeleKybController, or CrazyfliePidController
  /// (controller="crazyflie_pid").
  const FlightController& controller() const { return *flight_; }

 private:
  struct Config;    // the parameters, parsed: one per parameter set (PluginSetup::shared)
  struct Airframe;  // what the rotors' places make of them: one per parameter set and artifact type

  const FlightController& flight() const { return *flight_; }

  // FlightInputs, for the controller
  Setpoint reference(double t, double dt) override { return references_.at(t, dt); }
  bool holdsHeading() const override { return references_.holdsHeading(); }
  void position(Pose& pose, Vec3& velocity) const override;
  Vec3 bodyRates() const override {
    const BodyState s = artifact().state();
    return s.pose.orientation.conjugate() * s.angular_velocity;
  }
  Nanoseconds positionStamp() const override { return have_pose_ ? pose_.stamp : -1; }
  const ImuMeasurement* imu() const override { return imu_; }

  // With thousands of robots a step is bound by memory latency: what every step reads comes
  // first, held in the driver (not behind pointers of its own), so that it spans few cache lines;
  // what members of one type share (the inner loop's gains, the rotors' constants) is one object
  // they all point to, which stays in the cache; what only some features read comes last.
  bool have_pose_ = false;
  bool ground_effect_ = false;
  // the controller flying it, chosen at load; before, TeleKyb's, which answers what a program asks
  // before the start (the command levels it takes) and keeps a command given then
  std::unique_ptr<FlightController> flight_ = std::make_unique<TeleKybController>();
  std::array<double, kMaxRotors> commanded_speeds_{};  // the first rotorCount() in use
  bool landed_ = false;  // reference="follow": it came down on the robot it follows, motors stopped
  Vehicle vehicle_;
  PoseMeasurement pose_;
  References references_;
  plugins::Hold hold_;  // hold="ARTIFACT": takes it at hold_time (a gripper, a hook)
  Wind wind_;
  std::optional<Downwash> downwash_;
  double ground_z_ = 0;  // the ground plane's height (-inf: none)
  // varied constants (vary): the rotor constants' factors, the mean wind's offset; the airframe
  // holds the configured rotor model they scale
  std::shared_ptr<const Airframe> frame_;
  std::array<double, 4> rotor_factors_{1.0, 1.0, 1.0, 1.0};
  Vec3 wind_offset_ = Vec3::Zero();
  // the battery varies (battery_volts) with a battery model, or the Crazyflie's held battery
  bool battery_varies_ = false;
  double crazyflie_battery_ = 4.2;  // V, crazyflie_battery_volts
  const ImuMeasurement* imu_ = nullptr;  // the IMU's latest sample, read in place (a controller's estimator)
};

}  // namespace ssx::quadrotor
