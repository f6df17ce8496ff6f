#pragma once
// quadrotor: the driver of a quadrotor. Rotor model, cascaded controller (outer position loop in
// floating point, inner attitude loop in integers fed by the IMU), and reference sources.
//
// Parameters: kParameters in quadrotor_driver.cpp, or `ssx plugins --params quadrotor`. Every
// RotorParams field by its name overrides the preset.
//
// Timing: the driver runs every `period` steps and integrates its motors over that period; the
// position loop (outer_rate_hz) and the attitude loop (inner_rate_hz) run every k of its runs,
// so their periods must be whole multiples of the driver's (checked while loading). The attitude
// loop reads the IMU's latest sample.
//
// Needs a sensor producing ssx::ImuMeasurement on the artifact (the `imu` plugin). Uses the first
// sensor producing ssx::PoseMeasurement (a motion-capture stand-in) for position and velocity,
// else the ground truth. The formation needs a `range` sensor; its members must be one swarm
// (consecutive artifacts), member i at artifact index (own - own i + i).
#include "quadrotor_model.hpp"

#include <ssx/ssx.hpp>

#include <array>
#include <memory>
#include <optional>
#include <span>

namespace ssx::quadrotor {

class QuadrotorDriver final : public Driver, public CommandInterface, public MetricSource {
 public:
  static constexpr const char* kDoc =
      "rotor model, integer attitude loop on IMU counts, position loop, reference sources";
  static constexpr ssx_plugin_param kParameters[] = {
      param::choice("preset", "mk_quad", "mk_quad hummingbird crazyflie", "rotor and motor constants to start from"),
      param::real("thrust_coefficient", "", "N s^2", param::positive(), "thrust per squared rotor speed (default: the preset's)"),
      param::real("moment_constant", "", "m", param::positive(), "drag torque per thrust (default: the preset's)"),
      param::real("time_constant_up", "", "s", param::positive(), "motor time constant, speeding up (default: the preset's)"),
      param::real("time_constant_down", "", "s", param::positive(), "motor time constant, slowing down (default: the preset's)"),
      param::real("max_rotor_speed", "", "rad/s", param::positive(), "(default: the preset's)"),
      param::real("min_rotor_speed", "", "rad/s", param::nonNegative(), "below max_rotor_speed (default: the preset's)"),
      param::real("rotor_drag_coefficient", "", "N s/m", param::nonNegative(), "rotor drag (default: the preset's)"),
      param::real("rolling_moment_coefficient", "", "N m s/m", param::nonNegative(), "rolling moment (default: the preset's)"),
      param::real("rotor_radius", "", "m", param::positive(), "propeller radius, for ground effect (default: the preset's)"),
      param::flag("ground_effect", "false", "thrust gain near the ground (Cheeseman-Bennett), per rotor"),
      param::flag("battery", "false", "a battery whose voltage sags with current and charge drawn; thrust at a fixed command follows it"),
      param::real("battery_full_voltage", "16.8", "V", param::positive(), "open circuit when full"),
      param::real("battery_empty_voltage", "14", "V", param::positive(), "open circuit when the capacity is drawn (EST)"),
      param::real("battery_capacity", "2.2", "Ah", param::positive(), "capacity (EST)"),
      param::real("battery_resistance", "0.04", "ohm", param::nonNegative(), "internal resistance (EST)"),
      param::real("battery_efficiency", "0.6", "", param::positive() & param::atMost(1), "mechanical / electrical power (EST)"),
      param::real("battery_initial_charge", "1", "", param::nonNegative() & param::atMost(1), "fraction of the capacity at the start"),
      param::real("battery_nominal_voltage", "15.5", "V", param::positive(), "voltage at which the rotor model's thrust holds (MK law)"),
      param::real("battery_zero_thrust_voltage", "7.575", "V", param::nonNegative(),
                  "the MK law's offset: thrust at a fixed command is proportional to U minus this"),
      param::flag("thrust_estimator", "false",
                  "the controller estimates thrust per command online (from the position source's velocity) and corrects for it"),
      param::real("thrust_estimator_time_constant", "1", "s", param::positive(), "its low-pass time constant"),
      param::flag("command_link", "false",
                  "the inner loop gets commands as over the MK serial link: 8-bit thrust in steps of m g / 128, angles in steps"),
      param::real("command_angle_step_deg", "0.5", "deg", param::positive() & param::atMost(10),
                  "roll and pitch step on the link (EST)"),
      param::real("command_delay", "0", "s", param::nonNegative() & param::atMost(1),
                  "the outer loop's commands reach the inner loop this late (a whole number of inner-loop periods)"),
      param::vec3("wind", "0 0 0", "m/s", param::any(), "mean wind, world frame"),
      param::real("turbulence_w20", "0", "m/s", param::nonNegative() & param::atMost(50),
                  "Dryden turbulence (MIL-F-8785C): the wind speed at 20 ft it is scaled by (0: none; light 7.7, moderate 15.4)"),
      param::real("turbulence_min_airspeed", "1", "m/s", param::positive(),
                  "the airspeed the turbulence's length scales are travelled at, at least (frozen turbulence; EST)"),
      param::vec3("gust", "0 0 0", "m/s", param::any(), "amplitude of one 1-cosine gust, world frame"),
      param::real("gust_start", "0", "s", param::nonNegative(), "when the gust begins"),
      param::real("gust_duration", "1", "s", param::positive(), "how long it lasts (rises and falls)"),
      param::flag("downwash", "false", "robots above push this one down (gym-pybullet-drones' model)"),
      param::real("downwash_c1", "2267.18", "N", param::positive(), "model coefficient (fitted on Crazyflies)"),
      param::real("downwash_c2", "0.16", "", param::any(), "model coefficient (fitted on Crazyflies)"),
      param::real("downwash_c3", "-0.11", "m", param::any(), "model coefficient (fitted on Crazyflies)"),
      param::real("downwash_range", "3", "m", param::positive(), "robots farther than this are not looked at"),
      param::real("downwash_min_height", "0.1", "m", param::nonNegative(),
                  "robots less than this above count as beside, not above (the fitted form diverges; EST)"),
      param::vec3("controller_inertia", "", "kg m^2", param::positive(),
                  "diagonal inertia the inner loop assumes (default: the model's)"),
      param::real("rotor_inertia", "", "kg m^2", param::nonNegative(), "(default: the preset's)"),
      param::text("rotors", "rotor0 rotor1 rotor2 rotor3", "physic node names of the rotors (4 to 8)"),
      param::text("directions", "1 -1 1 -1", "spin of each rotor: 1 counter-clockwise seen from above, -1 clockwise"),
      param::rate("outer_rate_hz", "50", param::positive(), "position loop rate"),
      param::rate("inner_rate_hz", "500", param::positive(), "attitude loop rate; it reads the IMU's latest sample"),
      param::real("attitude_kp", "200", "1/s^2", param::positive() & param::atMost(InnerLoopLimits::attitude_kp), "attitude gain"),
      param::real("attitude_kd", "25", "1/s", param::positive() & param::atMost(InnerLoopLimits::attitude_kd), "body rate gain"),
      param::real("yaw_rate_kp", "8", "1/s", param::positive() & param::atMost(InnerLoopLimits::yaw_rate_kp), "yaw rate gain"),
      param::real("heading_kp", "2", "1/s", param::nonNegative() & param::atMost(50),
                  "heading gain for external set-points (their yaw); the other references give a yaw rate only"),
      param::real("max_angular_acceleration", "400", "rad/s^2",
                  param::positive() & param::atMost(InnerLoopLimits::max_angular_acceleration), "per axis"),
      param::real("filter_gyro_weight", "0.998", "", param::positive() & param::atMost(1),
                  "complementary filter: weight of the gyro path per step"),
      param::vec3("position_kp", "9 9 9", "1/s^2", param::nonNegative(), "position gains"),
      param::vec3("position_kd", "7.5 7.5 7.5", "1/s", param::nonNegative(), "velocity gains"),
      param::vec3("position_ki", "4.5 4.5 0", "1/s^3", param::nonNegative(), "integral gains"),
      param::real("integral_limit", "2", "m s", param::positive(), "per axis"),
      param::real("max_tilt_deg", "30", "deg", param::positive() & param::below(90), "largest roll or pitch commanded"),
      param::real("max_thrust", "", "N", param::positive(), "largest thrust commanded (default: 0.95 of the rotors' total)"),
      param::real("controller_mass", "", "kg", param::positive(), "the mass the controller assumes (default: the model's)"),
      param::choice("reference", "hover", "hover eight_horizontal eight_vertical external formation",
                    "where the set-point comes from"),
      param::vec3("target", "", "m", param::any(), "hover point (default: the start plus offset)"),
      param::vec3("offset", "0 0 0", "m", param::any(), "hover point, or the formation's start, relative to the start"),
      param::vec3("center", "", "m", param::any(), "figure eight centre (default: the start plus center_offset)"),
      param::vec3("center_offset", "0 0 0", "m", param::any(), "figure eight centre relative to the start"),
      param::real("amplitude", "1", "m", param::positive(), "figure eight amplitude A"),
      param::real("eight_period", "12", "s", param::positive(), "figure eight period T"),
      param::real("yaw_rate", "0.2", "rad/s", param::any(), "figure eight yaw rate"),
      param::real("start_time", "0", "s", param::any(), "figure eight or formation start; before it the vehicle holds"),
      param::integer("formation_index", "0", param::nonNegative(), "this member's index in the formation"),
      param::integer("formation_size", "70", param::between(1, 10'000'000), "members in the formation"),
      param::real("formation_radius", "4", "m", param::positive(), "sphere radius"),
      param::vec3("formation_center", "0 0 5", "m", param::any(), "sphere centre"),
      param::real("formation_gain", "0.2", "m/s", param::positive(), "gain of the shape potentials"),
      param::real("formation_max_speed", "1", "m/s", param::positive(), "top speed of the virtual point"),
      param::real("formation_anchor_gain", "0.5", "1/s", param::nonNegative(), "pull towards the own target"),
      param::real("obstacle_distance", "0.5", "m", param::positive(), "obstacles repel inside it"),
      param::real("obstacle_saturation", "0.2", "m", param::positive(), "the repulsion is saturated inside it"),
  };
  static void validate(const Descriptor& params, const PluginContext& context);
  void configure(const Descriptor& params, PluginSetup& setup) override;
  void step(const StepInfo& info) override;
  void saveState(StateWriter& out) const override;
  void loadState(StateReader& in) override;
  /// Every level: position and velocity through the position loop, attitude and rates through the
  /// inner loop, rotors straight to the motors (the loops above keep their state but do not act).
  bool acceptsCommand(CommandLevel) const override { return true; }
  std::size_t rotorCount() const override { return rotors_->size(); }
  void setCommand(const Command& command) override;
  CommandLevel commandLevel() const override { return level_; }
  Setpoint currentSetpoint() const override { return current_; }
  /// In formation: `formation_error`, the mean over the members its range sensor sees whose
  /// places on the sphere are within sensing range of its own, of | distance - desired distance |
  /// (m), as of its latest range measurement (NaN when it sees none).
  std::vector<std::string> metricNames() const override;
  void metrics(std::vector<Metric>& out) const override;

  /// For tests: the rotor model and the controller's pieces.
  const RotorModel& rotors() const { return *rotors_; }
  const InnerLoopFixed& innerLoop() const { return *inner_; }  ///< its gains (the estimate is the driver's)
  const AttitudeEstimate& attitudeEstimate() const { return estimate_; }
  const AttitudeCommand& attitudeCommand() const { return attitude_; }

 private:
  struct Config;    // the parameters, parsed: one per parameter set (PluginSetup::shared)
  struct Airframe;  // what the rotors' places make of them: one per parameter set and artifact type
  Setpoint reference(double t) const;
  void outerLoop(const StepInfo& info);
  AttitudeCommand overLink(const AttitudeCommand& command) const;  // as command_link carries it
  static InnerCommand toInner(const AttitudeCommand& command);
  void formationStep(double dt);
  double desiredDistance(std::size_t member);
  std::span<const RangeMeasurement::Detection> seen() const {
    return range_ != nullptr ? std::span<const RangeMeasurement::Detection>(range_->detections)
                             : std::span<const RangeMeasurement::Detection>();
  }

  // With thousands of robots a step is bound by memory latency: what every step reads comes
  // first, held in the driver (not behind pointers of its own), so that it spans few cache lines;
  // what members of one type share (the inner loop's gains, the rotors' constants) is one object
  // they all point to, which stays in the cache; what only some features read comes last.
  // -- read every step
  enum class Source { Hover, Eight, External, Formation } source_ = Source::Hover;
  CommandLevel level_ = CommandLevel::Position;  // External at a lower level than position
  bool imu_seen_ = false;  // a sample has arrived
  bool have_pose_ = false;
  bool ground_effect_ = false;
  bool thrust_estimator_ = false;
  bool command_link_ = false;
  bool downwash_ = false;
  bool wind_or_gust_ = false;  // wind_, gust_ or turbulence_w20_ is not zero
  std::int64_t inner_runs_ = 1, outer_runs_ = 10;  // loop periods in runs of the driver
  double outer_dt_ = 0.02;
  const ImuMeasurement* imu_ = nullptr;
  std::shared_ptr<const InnerLoopFixed> inner_;  // gains and mixer
  AttitudeEstimate estimate_;
  InnerCommand command_;
  std::vector<InnerCommand> command_queue_;  // a ring: the commands of the last command_delay
  std::size_t queue_at_ = 0;
  std::array<double, kMaxRotors> commanded_speeds_{};  // the first rotors_->size() in use
  std::optional<RotorModel> rotors_;
  Vec3 com_in_root_ = Vec3::Zero();
  // -- read every outer-loop run
  std::optional<PositionController> outer_;
  AttitudeCommand attitude_;
  Setpoint current_;
  PoseMeasurement pose_;
  Setpoint hover_;
  double start_time_ = 0;
  // the formation
  const RangeMeasurement* range_ = nullptr;  // the range sensor's latest measurement
  std::size_t formation_index_ = 0, formation_base_ = 0;
  Vec3 virtual_point_ = Vec3::Zero();
  Vec3 virtual_velocity_ = Vec3::Zero();
  Vec3 own_target_ = Vec3::Zero();
  std::vector<std::pair<std::size_t, double>> desired_distance_;  // member -> d*, sorted; filled as met
  Formation formation_;
  // -- features, read when they are on
  Setpoint external_;
  Vec3 command_velocity_ = Vec3::Zero();  // the velocity level's command
  double command_yaw_rate_ = 0;
  Vec3 velocity_point_ = Vec3::Zero();  // the velocity level's reference point, moved at the command
  FigureEight eight_;
  double heading_kp_ = 2.0;  // 1/s, external set-points' yaw
  std::optional<Battery> battery_;
  double estimator_tau_ = 1.0, thrust_ratio_ = 1.0;  // estimated actual / expected thrust per command
  Vec3 last_velocity_ = Vec3::Zero();                 // the estimator's, at the last outer run
  bool have_last_velocity_ = false;
  double controller_mass_ = 0;
  double angle_step_ = 0;  // rad
  Vec3 wind_ = Vec3::Zero(), gust_ = Vec3::Zero();
  double gust_start_ = 0, gust_duration_ = 1;
  double turbulence_w20_ = 0, min_airspeed_ = 1;
  DrydenTurbulence turbulence_;
  double downwash_c_[3] = {0, 0, 0}, downwash_range_ = 3, downwash_min_dz_ = 0.1;
  std::vector<SpatialIndex::Hit> above_;  // neighbours, reused
  double ground_z_ = 0;                   // the ground plane's height (-inf: none)
  std::array<double, kMaxRotors> gains_{};  // per rotor thrust gains, handed to the rotor model
};

}  // namespace ssx::quadrotor
