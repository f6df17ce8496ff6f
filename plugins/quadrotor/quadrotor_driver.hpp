#pragma once
// quadrotor: the driver of a quadrotor. Rotor model, cascaded controller (outer position loop in
// floating point, inner attitude loop in integers fed by the IMU), and reference sources.
//
// Parameters (artifact file; every RotorParams field by its name overrides the preset):
//   preset             mk_quad (default), hummingbird, crazyflie
//   thrust_coefficient, moment_constant, time_constant_up, time_constant_down, max_rotor_speed,
//   min_rotor_speed, rotor_drag_coefficient, rolling_moment_coefficient, rotor_inertia
//   rotors             physic node names of the rotors (default "rotor0 rotor1 rotor2 rotor3")
//   directions         spin of each, +1 counter-clockwise seen from above (default "1 -1 1 -1")
//   outer_rate_hz      position loop rate (default 50)
//   inner_rate_hz      attitude loop rate (default 500); the IMU should run at least as fast
//   attitude_kp, attitude_kd, yaw_rate_kp, max_angular_acceleration, filter_gyro_weight
//   position_kp, position_kd, position_ki ("x y z"), integral_limit, max_tilt_deg, max_thrust
//   controller_mass    the mass the controller assumes (default: the model's)
//   reference          hover (default), eight_horizontal, eight_vertical, external, formation
//   target / offset    hover point, or the start plus offset (default 0 0 0)
//   center, amplitude, period, yaw_rate, start_time   figure eight (center default: the start
//                      plus center_offset; before start_time the vehicle holds the centre)
//   formation_index, formation_size, formation_radius, formation_center, formation_gain,
//   formation_max_speed, formation_anchor_gain, obstacle_distance, obstacle_saturation
//                      formation on a sphere; needs a `range` sensor; the members must be one
//                      swarm (consecutive artifacts), member i at artifact index (own - own i + i)
//
// Needs a sensor producing ssx::ImuMeasurement on the artifact (the `imu` plugin). Uses the first
// sensor producing ssx::PoseMeasurement (a motion-capture stand-in) for position and velocity,
// else the ground truth.
#include "quadrotor_model.hpp"

#include <ssx/ssx.hpp>

#include <optional>

namespace ssx::quadrotor {

class QuadrotorDriver final : public Driver, public SetpointInterface {
 public:
  void configure(const Descriptor& params) override;
  void step(const StepInfo& info) override;
  void setSetpoint(const Setpoint& setpoint) override;
  Setpoint currentSetpoint() const override { return current_; }

  /// For tests: the rotor model and the controller's pieces.
  const RotorModel& rotors() const { return *rotors_; }
  const InnerLoopFixed& innerLoop() const { return *inner_; }
  const AttitudeCommand& attitudeCommand() const { return attitude_; }

 private:
  Setpoint reference(double t) const;

  // held in the driver, not behind pointers: with thousands of robots a step is bound by memory
  // latency, and every separate allocation is one more cache miss per robot and step
  std::optional<RotorModel> rotors_;
  std::optional<InnerLoopFixed> inner_;
  std::optional<PositionController> outer_;
  InnerCommand command_;
  AttitudeCommand attitude_;
  std::vector<double> commanded_speeds_;
  std::int64_t inner_steps_ = 1, outer_steps_ = 10;
  double outer_dt_ = 0.02;
  enum class Source { Hover, Eight, External, Formation } source_ = Source::Hover;
  void formationStep(double dt);
  Formation formation_;
  std::size_t formation_index_ = 0, formation_base_ = 0;
  Vec3 virtual_point_ = Vec3::Zero();
  Vec3 virtual_velocity_ = Vec3::Zero();
  std::vector<RangeMeasurement::Detection> seen_;
  Vec3 own_target_ = Vec3::Zero();
  std::vector<std::pair<std::size_t, double>> desired_distance_;  // member -> d*, sorted; filled as met
  double desiredDistance(std::size_t member);
  Setpoint hover_;
  Setpoint external_;
  FigureEight eight_;
  double start_time_ = 0;
  Setpoint current_;
  const ImuMeasurement* imu_ = nullptr;
  bool imu_fresh_ = false;
  PoseMeasurement pose_;
  bool have_pose_ = false;
  Vec3 com_in_root_ = Vec3::Zero();
};

}  // namespace ssx::quadrotor
