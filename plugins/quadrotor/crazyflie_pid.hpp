#pragma once
// The Crazyflie firmware's default controller (crazyflie-firmware 2025.12.1: controller_pid.c,
// position_controller_pid.c, attitude_pid_controller.c, pid.c, power_distribution_quadrotor.c; gains
// from platform_defaults_cf2.h), written from its description:
// - position P(I) and velocity PI at 100 Hz, x and y in the frame turned by the vehicle's yaw; no
//   feed-forward of the set-point's motion (the firmware drops it), the velocity asked for clamped
//   to 1.1 m/s per axis and the tilt to 20 degrees;
// - thrust = 36000 + 1000 * the vertical velocity PI, at least 20000, no tilt compensation;
// - attitude PI and rate PID at 500 Hz, in degrees, D on the measurement, integrals clamped;
// - the quad-X mixer in the firmware's 0-65535 command units (half the roll and pitch outputs,
//   truncated), capped by giving up collective thrust first;
// - each motor's command is newtons through the battery compensation (CrazyflieThrustCurve), and a
//   rotor speed through the thrust coefficient.
// Signs are ssx's (x forward, y left, z up; a positive pitch tilts the thrust towards +x); the
// firmware's pitch has the other sign, which changes nothing else.
//
// Its loops fly on the position source's state, or (crazyflie_estimator="kalman") on the firmware's
// Kalman filter fed with the IMU and the position source (crazyflie_kalman.hpp).
//
// It takes position and velocity commands. The quadrotor driver runs it with controller="crazyflie_pid".
#include "controller.hpp"
#include "crazyflie_kalman.hpp"
#include "crazyflie_thrust.hpp"
#include "quadrotor_model.hpp"

#include <array>
#include <memory>
#include <vector>

namespace ssx::quadrotor {

/// The quadrotor driver's choice of controller, and this one's settings (part "controller").
inline constexpr ssx_plugin_param kControllerChoiceParameters[] = {
    param::choice("controller", "telekyb", "telekyb crazyflie_pid",
                  "the flight controller: TeleKyb's cascade (the mk_quad's; every command level) or the Crazyflie "
                  "firmware's PID cascade (four rotors in an X; position and velocity commands; the crazyflie "
                  "preset's)"),
    param::real("crazyflie_position_rate_hz", "100", "Hz", param::positive(),
                "crazyflie_pid: position and velocity loops (its period a whole multiple of the driver's)"),
    param::real("crazyflie_attitude_rate_hz", "500", "Hz", param::positive(),
                "crazyflie_pid: attitude and rate loops (its period a whole multiple of the driver's)"),
    param::choice(
        "crazyflie_estimator", "truth", "truth kalman",
        "crazyflie_pid: the state its loops fly on: truth (the position source's pose and velocity as they come: "
        "motion capture, else the truth) or kalman (the firmware's extended Kalman filter fed with the IMU and "
        "the position source's positions, as a Crazyflie flying with motion capture)"),
    param::real("crazyflie_battery_volts", "4.2", "V", param::atLeast(2) & param::atMost(4.35),
                "crazyflie_pid without battery=\"true\": the battery voltage its thrust compensation sees and its "
                "motors get (held constant)"),
};

/// pid.c's element.
struct PidGains {
  double kp = 0, ki = 0, kd = 0;
  double integral_limit = 5000;  ///< |integral| at most this (the firmware's default: no real limit)
  double output_limit = 0;       ///< |output| at most this; 0: no limit
};

class Pid {
 public:
  Pid() = default;
  explicit Pid(const PidGains& gains) : g_(gains) {}
  /// One update: kp e + ki (integral of e) + kd (-d measured / dt), D on the measurement (a
  /// set-point step gives no kick). `wrap_degrees`: the error is wrapped to +-180.
  double update(double desired, double measured, double dt, bool wrap_degrees = false);
  void reset();
  double integral() const { return integral_; }
  void setIntegral(double integral) { integral_ = integral; }
  void save(StateWriter& out) const;
  void load(StateReader& in);

 private:
  PidGains g_;
  double integral_ = 0, previous_ = 0;
  bool started_ = false;
};

/// The firmware's two-pole low-pass (filter.c lpf2p, a Butterworth biquad), as it filters the gyro
/// at 80 Hz (sensors_bmi088_bmp3xx.c).
class LowPass2 {
 public:
  LowPass2() = default;
  LowPass2(double sample_hz, double cutoff_hz);
  double apply(double sample);
  double state(int k) const { return k == 0 ? d1_ : d2_; }
  void setState(double d1, double d2) { d1_ = d1, d2_ = d2; }

 private:
  double b0_ = 1, b1_ = 0, b2_ = 0, a1_ = 0, a2_ = 0;
  double d1_ = 0, d2_ = 0;
};

/// The firmware's defaults (platform_defaults_cf2.h).
struct CrazyfliePidGains {
  PidGains position_xy{2, 0, 0};
  PidGains position_z{2, 0.5, 0};
  double velocity_max_xy = 1.1, velocity_max_z = 1.1;  ///< m/s: 1.0 and max(zVelMax, 0.5), each x 1.1
  PidGains velocity_xy{25, 1, 0, 5000, 22};             ///< degrees of tilt per m/s; output +-1.1 x 20 degrees
  PidGains velocity_z{25, 15, 0, 5000, 65535.0 / 2 / 1000};
  double tilt_max_deg = 20;
  double thrust_base = 36000, thrust_scale = 1000, thrust_min = 20000;
  PidGains attitude_rp{6, 3, 0, 20};
  PidGains attitude_yaw{6, 1, 0.35, 360};
  PidGains rate_rp{250, 500, 2.5, 33.3, 32767};
  PidGains rate_yaw{120, 16.7, 0, 166.7, 32767};
  double position_rate_hz = 100, attitude_rate_hz = 500;
  double gyro_cutoff_hz = 80;  ///< the gyro's low-pass (0: none)
  bool kalman = false;         ///< fly on the firmware's Kalman filter's estimate (else on the position source's)
  CrazyflieKalmanParams kalman_params;
  double kalman_rate_hz = 100;  ///< the filter's prediction rate
};

class CrazyfliePidController final : public FlightController {
 public:
  /// `rotors`: four rotors in an X (none on an axis); `rotor`: kF for the rotor speeds; stepped at
  /// gains.attitude_rate_hz. std::invalid_argument for another layout or rates that do not divide.
  CrazyfliePidController(const CrazyfliePidGains& gains, const std::vector<Rotor>& rotors, const RotorParams& rotor,
                         const CrazyflieThrustCurve& curve = CrazyflieThrustCurve::propellers21plus());

  /// A battery held at `volts` (4.2 V until told): what the compensation sees and what the motors get.
  void setBatteryVoltage(double volts) {
    filter_.reset(volts);
    motor_volts_ = volts;
  }
  /// A battery measured now at `volts` (its terminal voltage): the motors get it; the compensation
  /// sees it through the firmware's low-pass, advanced by the driver's period (whole milliseconds).
  void measureBattery(double volts) {
    motor_volts_ = volts;
    filter_.update(volts, filter_ticks_);
  }
  /// The state the loops fly on (the filter's with `kalman`, else the position source's): position,
  /// velocity (world) and attitude.
  void flownState(FlightInputs& in, Pose& pose, Vec3& velocity) const;
  /// The voltage the compensation sees.
  double compensationVoltage() const { return filter_.volts(); }
  /// In a driver that runs every `run_seconds`: the attitude loop every `attitude_runs` runs, the
  /// position loop every `position_runs` (the mixer's output held between). By default every run
  /// is an attitude period and the position loop every gains' ratio of runs.
  void setRuns(std::int64_t attitude_runs, std::int64_t position_runs, double run_seconds);
  /// A vehicle placed in the air: the vertical velocity loop's integral holds `weight` (N) from the
  /// first step, as it would after hovering a while.
  void startInAir(double weight) override;
  void batteryVoltage(double volts, bool initial) override {
    if (initial)
      setBatteryVoltage(volts);
    else
      measureBattery(volts);
  }

  /// Position and velocity (the commander's high-level modes), attitude (cmd_rpyt: roll and pitch
  /// absolute, a yaw rate, a thrust) and body rates (the rate mode of the firmware's controller:
  /// the attitude loop bypassed). An attitude or rates command's collective thrust in N becomes
  /// the motor command that asks for a quarter of it per motor (the battery compensation's
  /// meaning of a command), at most 65535. Rotor speeds (rad/s) go to the motors as they are, the
  /// firmware's loops resting (as the firmware's motor power override, for learning at the lowest
  /// level).
  bool accepts(CommandLevel level) const override {
    return level == CommandLevel::Position || level == CommandLevel::Velocity || level == CommandLevel::Attitude ||
           level == CommandLevel::Rates || level == CommandLevel::Rotors;
  }
  CommandLevel level() const override { return level_; }
  void setCommand(const Command& command, const Vec3& position) override;
  Setpoint currentSetpoint() const override { return current_; }
  Command command() const override;
  void step(std::int64_t run, double t, FlightInputs& in, std::span<double> speeds) override;
  void saveState(StateWriter& out) const override;
  void loadState(StateReader& in) override;

  /// What the velocity loop asks of the attitude loop: roll, pitch (degrees, ssx's signs) and the
  /// thrust command (0-65535), as the firmware logs them (controller.roll/pitch/cmd_thrust).
  std::array<double, 3> desiredAttitude() const { return {roll_deg_, pitch_deg_, thrust_}; }
  /// The velocity the position loop asks for (m/s, world frame).
  Vec3 desiredVelocity() const { return velocity_desired_; }
  /// The four motors' commands after mixing (the firmware's motorThrustUncapped: thrust plus or minus
  /// the roll, pitch and yaw outputs, not capped), in the rotors' order.
  std::array<double, 4> motorCommands() const { return motors_; }
  /// The four motors' thrusts (N) for their commands, as the firmware drives them: each command's PWM
  /// from the compensation, uncapped; then, if the highest is over 65535, the excess taken from every
  /// PWM (powerDistributionCap: the differential kept, the collective given up), floored at 0; each
  /// motor then gets that PWM of the battery's voltage.
  std::array<double, 4> motorThrusts() const;

 private:
  void positionLoop(double t, FlightInputs& in);
  void attitudeLoop(FlightInputs& in);
  void resetAll(double yaw_deg);
  void estimate(std::int64_t run, FlightInputs& in);

  CrazyfliePidGains g_;
  CrazyflieThrustCurve curve_;
  double thrust_coefficient_;
  std::array<std::array<double, 3>, 4> signs_{};  // per rotor: roll, pitch, yaw
  std::int64_t position_every_ = 5, attitude_every_ = 1;
  double position_dt_ = 0.01, attitude_dt_ = 0.002;
  BatteryFilter filter_;
  double motor_volts_ = 4.2;
  int filter_ticks_ = 2;  // the firmware's 1 ms ticks per run of the driver
  CommandLevel level_ = CommandLevel::Position;
  std::array<double, 4> rotor_command_{};  // rad/s, at the rotors level
  Setpoint current_;
  Vec3 command_velocity_ = Vec3::Zero();
  double command_yaw_rate_ = 0;  // rad/s
  Vec3 command_rates_ = Vec3::Zero();  // rad/s, body frame (rates level)
  // the loops
  Pid pos_[3], vel_[3], att_[3], rate_[3];
  LowPass2 gyro_filter_[3];
  Vec3 gyro_deg_ = Vec3::Zero();  // the filtered gyro, deg/s
  Vec3 velocity_desired_ = Vec3::Zero();
  double roll_deg_ = 0, pitch_deg_ = 0, yaw_target_deg_ = 0, thrust_ = 0;
  bool yaw_target_set_ = false;
  std::array<double, 4> motors_{};
  // the estimator (kalman): its filter (only then: a kilobyte a vehicle), the runs between
  // predictions, the latest samples taken
  std::unique_ptr<CrazyflieKalman> kalman_;
  std::int64_t predict_every_ = 5;
  double run_seconds_ = 0.002;
  bool kalman_started_ = false;
  Nanoseconds imu_stamp_ = -1, position_stamp_ = -2;
  // the gyroscope's bias, as the firmware measures it at rest before take-off (the mean over 1024
  // samples): here the mean of the IMU's reading less the true rate over its first 1024 samples
  Vec3 gyro_bias_sum_ = Vec3::Zero();
  int gyro_bias_samples_ = 0;
};

}  // namespace ssx::quadrotor
