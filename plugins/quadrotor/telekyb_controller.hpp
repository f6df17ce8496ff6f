#pragma once
// The mk_quad's flight controller (TeleKyb's cascade): an outer position loop in floating point and
// an inner attitude loop in integers fed by the IMU's raw counts, with the MK's command path (the
// serial link's quantisation, a command delay) and an optional online thrust estimator. It takes
// all five command levels: position and velocity through the position loop, attitude and rates
// through the inner loop, rotors straight to the motors (the loops above keep their state but do
// not act). Parameters: kTeleKybParameters.
#include "controller.hpp"
#include "quadrotor_model.hpp"

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

namespace ssx::quadrotor {

inline constexpr ssx_plugin_param kTeleKybParameters[] = {
    param::rate("outer_rate_hz", "50", param::positive(), "position loop rate"),
    param::rate("inner_rate_hz", "500", param::positive(), "attitude loop rate; it reads the IMU's latest sample"),
    param::real("attitude_kp", "200", "1/s^2", param::positive() & param::atMost(InnerLoopLimits::attitude_kp), "attitude gain"),
    param::real("attitude_kd", "25", "1/s", param::positive() & param::atMost(InnerLoopLimits::attitude_kd),
                "body rate gain (also the rates level's)"),
    param::real("yaw_rate_kp", "8", "1/s", param::positive() & param::atMost(InnerLoopLimits::yaw_rate_kp), "yaw rate gain"),
    param::real("heading_kp", "2", "1/s", param::nonNegative() & param::atMost(50),
                "heading gain for external set-points and trajectories (their yaw); the other references give a yaw "
                "rate only"),
    param::real("max_angular_acceleration", "400", "rad/s^2",
                param::positive() & param::atMost(InnerLoopLimits::max_angular_acceleration), "per axis"),
    param::real("filter_gyro_weight", "0.998", "", param::positive() & param::atMost(1),
                "complementary filter: weight of the gyro path per step"),
    param::vec3("controller_inertia", "", "kg m^2", param::positive(),
                "diagonal inertia the inner loop assumes (default: the model's)"),
    param::vec3("position_kp", "9 9 9", "1/s^2", param::nonNegative(), "position gains"),
    param::vec3("position_kd", "7.5 7.5 7.5", "1/s", param::nonNegative(), "velocity gains"),
    param::vec3("position_ki", "4.5 4.5 0", "1/s^3", param::nonNegative(), "integral gains"),
    param::real("integral_limit", "2", "m s", param::positive(), "per axis"),
    param::real("max_tilt_deg", "30", "deg", param::positive() & param::below(90), "largest roll or pitch commanded"),
    param::real("max_thrust", "", "N", param::positive(), "largest thrust commanded (default: 0.95 of the rotors' total)"),
    param::real("controller_mass", "", "kg", param::positive(), "the mass the controller assumes (default: the model's)"),
    param::flag("thrust_estimator", "false",
                "the controller estimates thrust per command online (from the position source's velocity) and corrects for it"),
    param::real("thrust_estimator_time_constant", "1", "s", param::positive(), "its low-pass time constant"),
    param::flag("command_link", "false",
                "the inner loop gets commands as over the MK serial link: 8-bit thrust in steps of m g / 128, angles in steps"),
    param::real("command_angle_step_deg", "0.5", "deg", param::positive() & param::atMost(10),
                "roll and pitch step on the link (EST)"),
    param::real("command_delay", "0", "s", param::nonNegative() & param::atMost(1),
                "the outer loop's commands reach the inner loop this late (a whole number of inner-loop periods)"),
};

/// The controller's parameters, parsed.
struct TeleKybParams {
  double inner_rate_hz, outer_rate_hz;
  double attitude_kp, attitude_kd, yaw_rate_kp, heading_kp, max_angular_acceleration, filter_gyro_weight;
  std::optional<Vec3> controller_inertia;
  std::optional<double> controller_mass, max_thrust;
  Vec3 position_kp, position_kd, position_ki;
  double integral_limit, max_tilt;  // m s, rad
  bool thrust_estimator = false;
  double estimator_tau;
  bool command_link = false;
  double angle_step, command_delay;  // rad, s
  explicit TeleKybParams(const Descriptor& params);
  /// command_delay in inner-loop periods (a whole number of them: checked, naming the parameter)
  std::size_t commandDelayTicks(const Descriptor& params, const PluginContext& context) const;
};

/// What the controller is built for: one per parameter set and artifact type.
struct TeleKybAirframe {
  double mass;                 ///< kg, the model's
  Mat3 inertia;                ///< what the inner loop assumes
  Eigen::MatrixXd mixer;       ///< InnerLoopParams::mixer
  double rotor_max_thrust;     ///< N, all rotors at full speed
};

class TeleKybController final : public FlightController {
 public:
  /// Subscribes to `imu` (the raw counts the inner loop reads) through `setup`. `context` gives
  /// the driver's period; `inner_key` names what makes its integer loop (shared by a swarm's members).
  void configure(const TeleKybParams& c, const TeleKybAirframe& frame, const RotorParams& rotor, const Descriptor& params,
                 const PluginContext& context, const Sensor& imu, PluginSetup& setup, const std::string& inner_key);
  /// A vehicle placed in the air holds its weight from the first step.
  void startInAir(double weight) override;

  bool accepts(CommandLevel level) const override { return level != CommandLevel::Wheels; }
  CommandLevel level() const override { return level_; }
  void setCommand(const Command& command, const Vec3& position) override;
  Setpoint currentSetpoint() const override { return current_; }
  /// As the vehicle took it: attitude after the serial link's rounding, rates in the inner loop's
  /// Q12/Q16 steps, all kMaxRotors rotor speeds (the driver keeps its rotors').
  Command command() const override;
  void step(std::int64_t run, double t, FlightInputs& in, std::span<double> speeds) override;
  void saveState(StateWriter& out) const override;
  void loadState(StateReader& in) override;

  const InnerLoopFixed& innerLoop() const { return *inner_; }
  const AttitudeEstimate& attitudeEstimate() const { return estimate_; }
  const AttitudeCommand& attitudeCommand() const { return attitude_; }
  double outerPeriod() const { return outer_dt_; }

 private:
  void outerLoop(double t, FlightInputs& in);
  AttitudeCommand overLink(const AttitudeCommand& command) const;  // as command_link carries it
  static InnerCommand toInner(const AttitudeCommand& c) {
    InnerCommand out;
    out.roll_q12 = static_cast<std::int32_t>(std::llround(c.roll * 4096.0));
    out.pitch_q12 = static_cast<std::int32_t>(std::llround(c.pitch * 4096.0));
    out.yaw_rate_q12 = static_cast<std::int32_t>(std::llround(c.yaw_rate * 4096.0));
    out.thrust_q16 = static_cast<std::int32_t>(std::llround(c.thrust * 65536.0));
    return out;
  }

  // (what every step reads first; see the driver)
  CommandLevel level_ = CommandLevel::Position;
  bool imu_seen_ = false;  // a sample has arrived
  bool thrust_estimator_ = false;
  bool command_link_ = false;
  std::int64_t inner_runs_ = 1, outer_runs_ = 10;  // loop periods in runs of the driver
  double outer_dt_ = 0.02;
  const ImuMeasurement* imu_ = nullptr;
  std::shared_ptr<const InnerLoopFixed> inner_;  // gains and mixer
  AttitudeEstimate estimate_;
  InnerCommand command_;
  std::vector<InnerCommand> command_queue_;  // a ring: the commands of the last command_delay
  std::size_t queue_at_ = 0;
  // -- read every outer-loop run
  std::optional<PositionController> outer_;
  AttitudeCommand attitude_;
  Setpoint current_;
  double heading_kp_ = 2.0;  // 1/s
  double gravity_ = 9.81;
  double controller_mass_ = 0;
  // -- the lower levels and features
  Vec3 command_velocity_ = Vec3::Zero();  // the velocity level's command
  double command_yaw_rate_ = 0;
  Vec3 velocity_point_ = Vec3::Zero();  // the velocity level's reference point, moved at the command
  std::array<double, kMaxRotors> rotor_command_{};  // the rotors level's speeds
  std::size_t rotor_count_ = 0;
  double estimator_tau_ = 1.0, thrust_ratio_ = 1.0;  // estimated actual / expected thrust per command
  Vec3 last_velocity_ = Vec3::Zero();                 // the estimator's, at the last outer run
  bool have_last_velocity_ = false;
  double angle_step_ = 0;  // rad
};

}  // namespace ssx::quadrotor
