// The Crazyflie firmware's default controller (crazyflie_pid.hpp).
#include "crazyflie_pid.hpp"

#include <ssx/error.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace ssx::quadrotor {

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

double wrap180(double degrees) {
  degrees = std::fmod(degrees + 180.0, 360.0);
  return (degrees < 0 ? degrees + 360.0 : degrees) - 180.0;
}

// roll, pitch, yaw (degrees) of an orientation, Z-Y-X
Vec3 eulerDegrees(const Quat& q) {
  const double roll = std::atan2(2 * (q.w() * q.x() + q.y() * q.z()), 1 - 2 * (q.x() * q.x() + q.y() * q.y()));
  const double pitch = std::asin(std::clamp(2 * (q.w() * q.y() - q.z() * q.x()), -1.0, 1.0));
  const double yaw = std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()));
  return Vec3(roll, pitch, yaw) * kDeg;
}

// x, y of a world vector in the frame turned by `yaw` (radians) about z
Vec3 intoYawFrame(const Vec3& v, double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {c * v.x() + s * v.y(), -s * v.x() + c * v.y(), v.z()};
}

double sign(double v) { return v > 0 ? 1.0 : -1.0; }

constexpr int kGyroBiasSamples = 1024;  // the firmware's gyro bias buffer (sensors_bmi088_bmp3xx.c)

}  // namespace

double Pid::update(double desired, double measured, double dt, bool wrap_degrees) {
  double error = desired - measured;
  if (wrap_degrees) error = wrap180(error);
  integral_ = std::clamp(integral_ + error * dt, -g_.integral_limit, g_.integral_limit);
  double change = started_ ? measured - previous_ : 0.0;
  if (wrap_degrees) change = wrap180(change);
  const double derivative = -change / dt;  // on the measurement: a set-point step gives no kick
  previous_ = measured;
  started_ = true;
  const double out = g_.kp * error + g_.ki * integral_ + g_.kd * derivative;
  return g_.output_limit > 0 ? std::clamp(out, -g_.output_limit, g_.output_limit) : out;
}

void Pid::reset() {
  integral_ = 0;
  started_ = false;
}

void Pid::save(StateWriter& out) const {
  out.write(integral_);
  out.write(previous_);
  out.write(started_);
}

void Pid::load(StateReader& in) {
  in.read(integral_);
  in.read(previous_);
  in.read(started_);
}

CrazyfliePidController::CrazyfliePidController(const CrazyfliePidGains& gains, const std::vector<Rotor>& rotors,
                                               const RotorParams& rotor, const CrazyflieThrustCurve& curve)
    : g_(gains),
      curve_(curve),
      thrust_coefficient_(rotor.thrust_coefficient),
      kalman_(gains.kalman ? std::make_unique<CrazyflieKalman>(gains.kalman_params) : nullptr) {
  if (rotors.size() != 4) throw std::invalid_argument("crazyflie_pid: four rotors, got " + std::to_string(rotors.size()));
  for (std::size_t i = 0; i < 4; ++i) {
    const Rotor& r = rotors[i];
    if (std::abs(r.position.x()) < 1e-6 || std::abs(r.position.y()) < 1e-6)
      throw std::invalid_argument("crazyflie_pid: the firmware's mixer is for an X frame; rotor " + std::to_string(i) +
                                  " stands on a body axis");
    // more thrust on the left rolls positive, at the rear pitches positive; a rotor whose reaction
    // torque points down (direction +1) yaws negative
    signs_[i] = {sign(r.position.y()), -sign(r.position.x()), -static_cast<double>(r.direction)};
  }
  const double ratio = g_.attitude_rate_hz / g_.position_rate_hz;
  if (!(ratio >= 1) || std::abs(ratio - std::round(ratio)) > 1e-9)
    throw std::invalid_argument("crazyflie_pid: the attitude rate must be a whole multiple of the position rate");
  position_every_ = static_cast<std::int64_t>(std::llround(ratio));
  position_dt_ = 1.0 / g_.position_rate_hz;
  attitude_dt_ = 1.0 / g_.attitude_rate_hz;
  const PidGains* p[3] = {&g_.position_xy, &g_.position_xy, &g_.position_z};
  const PidGains* v[3] = {&g_.velocity_xy, &g_.velocity_xy, &g_.velocity_z};
  const PidGains* a[3] = {&g_.attitude_rp, &g_.attitude_rp, &g_.attitude_yaw};
  const PidGains* w[3] = {&g_.rate_rp, &g_.rate_rp, &g_.rate_yaw};
  for (int k = 0; k < 3; ++k) pos_[k] = Pid(*p[k]), vel_[k] = Pid(*v[k]), att_[k] = Pid(*a[k]), rate_[k] = Pid(*w[k]);
  if (g_.gyro_cutoff_hz > 0)
    for (LowPass2& f : gyro_filter_) f = LowPass2(g_.attitude_rate_hz, g_.gyro_cutoff_hz);
}

LowPass2::LowPass2(double sample_hz, double cutoff_hz) {
  const double ohm = std::tan(std::numbers::pi * cutoff_hz / sample_hz);
  const double c = 1 + 2 * std::cos(std::numbers::pi / 4) * ohm + ohm * ohm;
  b0_ = ohm * ohm / c;
  b1_ = 2 * b0_;
  b2_ = b0_;
  a1_ = 2 * (ohm * ohm - 1) / c;
  a2_ = (1 - 2 * std::cos(std::numbers::pi / 4) * ohm + ohm * ohm) / c;
}

double LowPass2::apply(double sample) {
  const double d0 = sample - d1_ * a1_ - d2_ * a2_;
  const double out = d0 * b0_ + d1_ * b1_ + d2_ * b2_;
  d2_ = d1_;
  d1_ = d0;
  return out;
}

void CrazyfliePidController::setRuns(std::int64_t attitude_runs, std::int64_t position_runs, double run_seconds) {
  if (attitude_runs < 1 || position_runs < 1)
    throw std::invalid_argument("crazyflie_pid: its loops cannot run faster than the driver");
  attitude_every_ = attitude_runs;
  position_every_ = position_runs;
  attitude_dt_ = static_cast<double>(attitude_runs) * run_seconds;
  position_dt_ = static_cast<double>(position_runs) * run_seconds;
  filter_ticks_ = std::max(1, static_cast<int>(std::lround(run_seconds * 1000)));
  run_seconds_ = run_seconds;
  predict_every_ = std::max<std::int64_t>(1, std::llround(1.0 / (g_.kalman_rate_hz * run_seconds)));
  // the gyro filtered at every run of the driver (the firmware: every 1 ms sample)
  for (LowPass2& f : gyro_filter_) f = g_.gyro_cutoff_hz > 0 ? LowPass2(1.0 / run_seconds, g_.gyro_cutoff_hz) : LowPass2();
}

void CrazyfliePidController::startInAir(double weight) {
  if (weight <= 0) return;
  // thrust = base + scale (ki integral) at no error: the integral that gives the weight's command
  const double command = weight / 4 / curve_.thrust_max * 65535.0;
  vel_[2].setIntegral((command - g_.thrust_base) / (g_.thrust_scale * g_.velocity_z.ki));
}

void CrazyfliePidController::setCommand(const Command& command, const Vec3&) {
  level_ = command.level;
  if (command.level == CommandLevel::Position) {
    current_ = command.setpoint;
  } else if (command.level == CommandLevel::Velocity) {
    command_velocity_ = command.velocity;
    command_yaw_rate_ = command.yaw_rate;
  } else if (command.level == CommandLevel::Attitude || command.level == CommandLevel::Rates) {
    // the position and velocity loops rest; the attitude loop (or the rate loop alone) takes these
    thrust_ = std::clamp(command.thrust / 4 / curve_.thrust_max * 65535.0, 0.0, 65535.0);
    if (command.level == CommandLevel::Attitude) {
      roll_deg_ = command.roll * kDeg;
      pitch_deg_ = command.pitch * kDeg;
      command_yaw_rate_ = command.yaw_rate;
    } else {
      command_rates_ = command.body_rates;
    }
  } else if (command.level == CommandLevel::Rotors) {
    for (std::size_t i = 0; i < rotor_command_.size(); ++i)
      rotor_command_[i] = i < command.rotor_speeds.size() ? command.rotor_speeds[i] : 0.0;
  }
}

Command CrazyfliePidController::command() const {
  if (level_ == CommandLevel::Velocity) return Command::velocityYawRate(command_velocity_, command_yaw_rate_);
  const double thrust = thrust_ / 65535.0 * curve_.thrust_max * 4;
  if (level_ == CommandLevel::Attitude)
    return Command::attitude(roll_deg_ / kDeg, pitch_deg_ / kDeg, command_yaw_rate_, thrust);
  if (level_ == CommandLevel::Rates) return Command::rates(command_rates_, thrust);
  if (level_ == CommandLevel::Rotors) return Command::rotors({rotor_command_.begin(), rotor_command_.end()});
  return FlightController::command();
}

std::array<double, 4> CrazyfliePidController::motorThrusts() const {
  const double battery = filter_.volts();
  std::array<double, 4> out{};
  const double highest = std::max({motors_[0], motors_[1], motors_[2], motors_[3]});
  // the compensation reads the voltage the motors get and no PWM reaches the cap: each motor gives
  // the thrust asked for (the same numbers as the PWMs below, without inverting the curve)
  if (motor_volts_ == battery && battery >= 2.0 && highest / 65535.0 * curve_.thrust_max <= curve_.thrust(battery)) {
    for (std::size_t i = 0; i < 4; ++i) {
      const double newtons = std::max(motors_[i], 0.0) / 65535.0 * curve_.thrust_max;
      out[i] = newtons < curve_.thrust_min ? 0.0 : newtons;
    }
    return out;
  }
  std::array<double, 4> pwm{};
  for (std::size_t i = 0; i < 4; ++i) pwm[i] = curve_.uncappedPwm(motors_[i], battery);
  const double excess = std::max(0.0, std::max({pwm[0], pwm[1], pwm[2], pwm[3]}) - 65535.0);
  for (std::size_t i = 0; i < 4; ++i) {
    const double capped = std::max(0.0, pwm[i] - excess);
    out[i] = capped > 0 ? std::max(0.0, curve_.thrust(capped / 65535.0 * motor_volts_)) : 0.0;
  }
  return out;
}

void CrazyfliePidController::resetAll(double yaw_deg) {
  for (int k = 0; k < 3; ++k) pos_[k].reset(), vel_[k].reset(), att_[k].reset(), rate_[k].reset();
  yaw_target_deg_ = yaw_deg;
}

void CrazyfliePidController::flownState(FlightInputs& in, Pose& pose, Vec3& velocity) const {
  if (!kalman_) {  // (with the filter, step() has run it before the loops)
    in.position(pose, velocity);
    return;
  }
  pose.position = kalman_->position();
  pose.orientation = kalman_->attitude();
  velocity = kalman_->velocity();
}

// The estimator's part of a run, in estimator_kalman.c's order: the IMU's new sample added, the
// prediction when due, process noise, a new position, then the attitude error moved in.
void CrazyfliePidController::estimate(std::int64_t run, FlightInputs& in) {
  Pose measured;
  Vec3 velocity;
  in.position(measured, velocity);
  if (!kalman_started_) {
    kalman_->reset(measured.position, eulerDegrees(measured.orientation).z() / kDeg);
    kalman_started_ = true;
  }
  if (const ImuMeasurement* imu = in.imu(); imu != nullptr && imu->stamp != imu_stamp_) {
    if (gyro_bias_samples_ < kGyroBiasSamples) {
      gyro_bias_sum_ += imu->gyroscope - in.bodyRates();
      ++gyro_bias_samples_;
    }
    kalman_->addImu(imu->accelerometer, imu->gyroscope - gyro_bias_sum_ / gyro_bias_samples_);
    imu_stamp_ = imu->stamp;
  }
  if (run % predict_every_ == 0) kalman_->predict(static_cast<double>(predict_every_) * run_seconds_, thrust_ > 0);
  kalman_->addProcessNoise(run_seconds_);
  const Nanoseconds stamp = in.positionStamp();
  if (stamp < 0 || stamp != position_stamp_) {
    kalman_->updatePosition(measured.position);
    position_stamp_ = stamp;
  }
  kalman_->finalize();
}

void CrazyfliePidController::positionLoop(double t, FlightInputs& in) {
  const double dt = position_dt_;
  Pose pose;
  Vec3 velocity;
  flownState(in, pose, velocity);
  const Vec3 euler = eulerDegrees(pose.orientation);
  const double yaw = euler.z() / kDeg;
  if (!yaw_target_set_) yaw_target_deg_ = euler.z(), yaw_target_set_ = true;
  Vec3 desired_body;  // the velocity asked for: x, y in the yaw frame, z in the world's
  if (level_ == CommandLevel::Velocity) {
    desired_body = intoYawFrame(command_velocity_, yaw);
  } else {
    current_ = in.reference(t, dt);
    if (in.holdsHeading()) yaw_target_deg_ = current_.yaw * kDeg;
    const Vec3 target = intoYawFrame(current_.position, yaw), at = intoYawFrame(pose.position, yaw);
    desired_body.x() = std::clamp(pos_[0].update(target.x(), at.x(), dt), -g_.velocity_max_xy, g_.velocity_max_xy);
    desired_body.y() = std::clamp(pos_[1].update(target.y(), at.y(), dt), -g_.velocity_max_xy, g_.velocity_max_xy);
    desired_body.z() = std::clamp(pos_[2].update(target.z(), at.z(), dt), -g_.velocity_max_z, g_.velocity_max_z);
  }
  const double c = std::cos(yaw), s = std::sin(yaw);
  velocity_desired_ = {c * desired_body.x() - s * desired_body.y(), s * desired_body.x() + c * desired_body.y(),
                       desired_body.z()};
  // the velocity loop: tilt towards the velocity error, thrust from the vertical one
  const Vec3 measured = intoYawFrame(velocity, yaw);
  pitch_deg_ = std::clamp(vel_[0].update(desired_body.x(), measured.x(), dt), -g_.tilt_max_deg, g_.tilt_max_deg);
  roll_deg_ = std::clamp(-vel_[1].update(desired_body.y(), measured.y(), dt), -g_.tilt_max_deg, g_.tilt_max_deg);
  const double thrust = vel_[2].update(desired_body.z(), measured.z(), dt) * g_.thrust_scale + g_.thrust_base;
  thrust_ = std::clamp(std::max(thrust, g_.thrust_min), 0.0, 65535.0);
}

void CrazyfliePidController::attitudeLoop(FlightInputs& in) {
  const double dt = attitude_dt_;
  Pose pose;
  Vec3 velocity;
  flownState(in, pose, velocity);
  const Vec3 euler = eulerDegrees(pose.orientation);
  if (thrust_ <= 0) {  // as the firmware: every loop reset, the heading held where it is
    resetAll(euler.z());
    motors_.fill(0);
    return;
  }
  const bool commanded_yaw_rate = level_ == CommandLevel::Velocity || level_ == CommandLevel::Attitude;
  const double yaw_rate = commanded_yaw_rate ? command_yaw_rate_ : current_.yaw_rate;
  if (commanded_yaw_rate || !in.holdsHeading()) yaw_target_deg_ = wrap180(yaw_target_deg_ + yaw_rate * kDeg * dt);
  Vec3 rates_desired;
  if (level_ == CommandLevel::Rates) {
    rates_desired = command_rates_ * kDeg;
    yaw_target_deg_ = euler.z();  // a later attitude or velocity command holds the heading flown to
  } else {
    rates_desired = Vec3(att_[0].update(roll_deg_, euler.x(), dt), att_[1].update(pitch_deg_, euler.y(), dt),
                         att_[2].update(yaw_target_deg_, euler.z(), dt, true));
  }
  const Vec3& gyro = gyro_deg_;
  const double roll = rate_[0].update(rates_desired.x(), gyro.x(), dt);
  const double pitch = rate_[1].update(rates_desired.y(), gyro.y(), dt);
  const double yaw = rate_[2].update(rates_desired.z(), gyro.z(), dt);
  // the legacy mixer: half the roll and pitch outputs, truncated as the firmware's integers are
  const double r = std::trunc(roll / 2), p = std::trunc(pitch / 2), y = std::trunc(yaw);
  // not capped here: the firmware compensates each motor's command for the battery first and caps the
  // PWMs (motorThrusts)
  for (std::size_t i = 0; i < 4; ++i) motors_[i] = thrust_ + signs_[i][0] * r + signs_[i][1] * p + signs_[i][2] * y;
}

void CrazyfliePidController::step(std::int64_t run, double t, FlightInputs& in, std::span<double> speeds) {
  const Vec3 rates = in.bodyRates() * kDeg;
  for (int k = 0; k < 3; ++k) gyro_deg_[k] = gyro_filter_[k].apply(rates[k]);
  if (g_.kalman) estimate(run, in);
  const bool high_level = level_ == CommandLevel::Position || level_ == CommandLevel::Velocity;
  if (level_ == CommandLevel::Rotors) {  // the loops rest, the motors take the speeds asked for
    for (std::size_t i = 0; i < 4 && i < speeds.size(); ++i) speeds[i] = rotor_command_[i];
    return;
  }
  if (high_level && run % position_every_ == 0) positionLoop(t, in);
  if (run % attitude_every_ == 0) attitudeLoop(in);
  const std::array<double, 4> thrusts = motorThrusts();
  for (std::size_t i = 0; i < 4 && i < speeds.size(); ++i) speeds[i] = std::sqrt(thrusts[i] / thrust_coefficient_);
}

void CrazyfliePidController::saveState(StateWriter& out) const {
  for (int k = 0; k < 3; ++k) pos_[k].save(out), vel_[k].save(out), att_[k].save(out), rate_[k].save(out);
  out.write(static_cast<std::uint8_t>(level_));
  for (const double v : {current_.position.x(), current_.position.y(), current_.position.z(), current_.yaw,
                         current_.yaw_rate, command_velocity_.x(), command_velocity_.y(), command_velocity_.z(),
                         command_yaw_rate_, velocity_desired_.x(), velocity_desired_.y(), velocity_desired_.z(), roll_deg_,
                         pitch_deg_, yaw_target_deg_, thrust_, filter_.volts(), motor_volts_, command_rates_.x(),
                         command_rates_.y(), command_rates_.z()})
    out.write(v);
  out.write(yaw_target_set_);
  for (const double m : motors_) out.write(m);
  for (int k = 0; k < 3; ++k) out.write(gyro_filter_[k].state(0)), out.write(gyro_filter_[k].state(1)), out.write(gyro_deg_[k]);
  if (level_ == CommandLevel::Rotors)  // (only then: states saved at the other levels read as before)
    for (const double w : rotor_command_) out.write(w);
  if (g_.kalman) {  // (only with the estimator: states saved without it read as before)
    out.write(kalman_started_);
    out.write(imu_stamp_);
    out.write(position_stamp_);
    out.write(gyro_bias_sum_);
    out.write(static_cast<std::int32_t>(gyro_bias_samples_));
    kalman_->save(out);
  }
}

void CrazyfliePidController::loadState(StateReader& in) {
  for (int k = 0; k < 3; ++k) pos_[k].load(in), vel_[k].load(in), att_[k].load(in), rate_[k].load(in);
  std::uint8_t level = 0;
  in.read(level);
  if (level > static_cast<std::uint8_t>(CommandLevel::Rotors) || !accepts(static_cast<CommandLevel>(level)))
    throw StateError("crazyflie_pid: a saved command level this controller does not take (" +
                     std::to_string(level) + ")");
  level_ = static_cast<CommandLevel>(level);
  double filtered = 0;
  double* fields[] = {&current_.position.x(), &current_.position.y(), &current_.position.z(), &current_.yaw,
                      &current_.yaw_rate, &command_velocity_.x(), &command_velocity_.y(), &command_velocity_.z(),
                      &command_yaw_rate_, &velocity_desired_.x(), &velocity_desired_.y(), &velocity_desired_.z(),
                      &roll_deg_, &pitch_deg_, &yaw_target_deg_, &thrust_, &filtered, &motor_volts_,
                      &command_rates_.x(), &command_rates_.y(), &command_rates_.z()};
  for (double* f : fields) in.read(*f);
  filter_.reset(filtered);
  in.read(yaw_target_set_);
  for (double& m : motors_) in.read(m);
  for (int k = 0; k < 3; ++k) {
    const double d1 = in.get<double>(), d2 = in.get<double>();
    gyro_filter_[k].setState(d1, d2);
    in.read(gyro_deg_[k]);
  }
  if (level_ == CommandLevel::Rotors)
    for (double& w : rotor_command_) in.read(w);
  if (g_.kalman) {
    in.read(kalman_started_);
    in.read(imu_stamp_);
    in.read(position_stamp_);
    in.read(gyro_bias_sum_);
    std::int32_t samples = 0;
    in.read(samples);
    if (samples < 0 || samples > kGyroBiasSamples)
      throw StateError("crazyflie_pid: a saved count of gyroscope bias samples out of range");
    gyro_bias_samples_ = samples;
    kalman_->load(in);
  }
}

}  // namespace ssx::quadrotor
