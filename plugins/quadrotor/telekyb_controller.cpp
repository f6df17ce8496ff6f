#include "telekyb_controller.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace ssx::quadrotor {

namespace {

// m per axis: how far the velocity level's reference point may lead the vehicle
constexpr double kVelocityLeash = 0.3;

}  // namespace

TeleKybParams::TeleKybParams(const Descriptor& params) {
  inner_rate_hz = params.get<double>("inner_rate_hz");
  outer_rate_hz = params.get<double>("outer_rate_hz");
  attitude_kp = params.get<double>("attitude_kp");
  attitude_kd = params.get<double>("attitude_kd");
  yaw_rate_kp = params.get<double>("yaw_rate_kp");
  heading_kp = params.get<double>("heading_kp");
  max_angular_acceleration = params.get<double>("max_angular_acceleration");
  filter_gyro_weight = params.get<double>("filter_gyro_weight");
  controller_inertia = given<Vec3>(params, "controller_inertia");
  controller_mass = given<double>(params, "controller_mass");
  max_thrust = given<double>(params, "max_thrust");
  position_kp = params.get<Vec3>("position_kp");
  position_kd = params.get<Vec3>("position_kd");
  position_ki = params.get<Vec3>("position_ki");
  integral_limit = params.get<double>("integral_limit");
  max_tilt = params.get<double>("max_tilt_deg") * std::numbers::pi / 180.0;
  thrust_estimator = params.get<bool>("thrust_estimator");
  estimator_tau = params.get<double>("thrust_estimator_time_constant");
  command_link = params.get<bool>("command_link");
  angle_step = params.get<double>("command_angle_step_deg") * std::numbers::pi / 180.0;
  command_delay = params.get<double>("command_delay");
}

std::size_t TeleKybParams::commandDelayTicks(const Descriptor& params, const PluginContext& context) const {
  const double inner_period =
      static_cast<double>(runsPerPeriod(inner_rate_hz, context)) * toSeconds(context.period());
  const double ticks = command_delay / inner_period;
  if (std::abs(ticks - std::round(ticks)) > 1e-6)
    throw params.errorAt("command_delay", "command_delay must be a whole number of inner-loop periods (" +
                                              std::to_string(inner_period * 1e3) + " ms)");
  return static_cast<std::size_t>(std::llround(ticks));
}

void TeleKybController::configure(const TeleKybParams& c, const TeleKybAirframe& frame, const RotorParams& rp,
                                  const Descriptor& params, const PluginContext& context, const Sensor& imu,
                                  PluginSetup& setup, const std::string& inner_key) {
  const Environment& env = *context.environment;
  // the loops run every k runs of the driver (whole numbers: checked while loading)
  const double period = toSeconds(context.period());
  inner_runs_ = runsPerPeriod(c.inner_rate_hz, context);
  outer_runs_ = runsPerPeriod(c.outer_rate_hz, context);
  if (inner_runs_ < 1 || outer_runs_ < 1)
    throw params.error("inner_rate_hz and outer_rate_hz must not be faster than the driver runs");
  outer_dt_ = static_cast<double>(outer_runs_) * period;
  gravity_ = -env.settings().physics.gravity.z();

  // the IMU this controller reads
  imu_ = static_cast<const ImuMeasurement*>(&imu.latest());
  setup.subscribe<ImuMeasurement>(imu, [this](const ImuMeasurement&) { imu_seen_ = true; });

  // inner loop
  InnerLoopParams ip;
  ip.dt = static_cast<double>(inner_runs_) * period;
  ip.attitude_kp = c.attitude_kp;
  ip.attitude_kd = c.attitude_kd;
  ip.yaw_rate_kp = c.yaw_rate_kp;
  ip.max_angular_acceleration = c.max_angular_acceleration;
  ip.filter_gyro_weight = c.filter_gyro_weight;
  ip.gravity = gravity_;
  ip.inertia = frame.inertia;
  ip.min_rotor_speed = rp.min_rotor_speed;
  ip.max_rotor_speed = rp.max_rotor_speed;
  ip.mixer = frame.mixer;
  ip.max_thrust = frame.rotor_max_thrust;
  // the IMU's LSBs are known once it has been configured (it comes first in the artifact)
  ip.gyro_lsb = imu_->gyroscope_lsb > 0 ? imu_->gyroscope_lsb : ip.gyro_lsb;
  ip.accel_lsb = imu_->accelerometer_lsb > 0 ? imu_->accelerometer_lsb : ip.accel_lsb;
  // its integer gains and mixer: one copy for the members alike (the estimate is this controller's)
  char lsb_key[96];
  std::snprintf(lsb_key, sizeof lsb_key, " %a %a %a", ip.dt, ip.gyro_lsb, ip.accel_lsb);
  inner_ = setup.shared<InnerLoopFixed>(inner_key + lsb_key, [&] { return InnerLoopFixed(ip); });
  estimate_ = {};
  rotor_count_ = static_cast<std::size_t>(frame.mixer.rows());

  // outer loop
  PositionParams pp;
  pp.mass = c.controller_mass.value_or(frame.mass);
  pp.gravity = ip.gravity;
  pp.kp = c.position_kp;
  pp.kd = c.position_kd;
  pp.ki = c.position_ki;
  pp.integral_limit = c.integral_limit;
  pp.max_tilt = c.max_tilt;
  pp.max_thrust = c.max_thrust.value_or(0.95 * ip.max_thrust);
  pp.min_thrust = 0.05 * pp.max_thrust;
  outer_.emplace(pp);
  controller_mass_ = pp.mass;
  heading_kp_ = c.heading_kp;
  thrust_estimator_ = c.thrust_estimator;
  estimator_tau_ = c.estimator_tau;
  command_link_ = c.command_link;
  angle_step_ = c.angle_step;
  command_queue_.assign(c.commandDelayTicks(params, context) + 1, InnerCommand{});
}

void TeleKybController::startInAir(double weight) {
  if (weight > 0) command_.thrust_q16 = static_cast<std::int32_t>(std::llround(weight * 65536.0));
  // before the first delayed command arrives, the inner loop has the initial one
  std::fill(command_queue_.begin(), command_queue_.end(), command_);
}

Command TeleKybController::command() const {
  switch (level_) {
    case CommandLevel::Position:
      return Command::position(current_);
    case CommandLevel::Velocity:
      return Command::velocityYawRate(command_velocity_, command_yaw_rate_);
    case CommandLevel::Attitude:
      return Command::attitude(attitude_.roll, attitude_.pitch, attitude_.yaw_rate, attitude_.thrust);
    case CommandLevel::Rates:
      return Command::rates(Vec3(command_.roll_q12, command_.pitch_q12, command_.yaw_rate_q12) / 4096.0,
                            command_.thrust_q16 / 65536.0);
    case CommandLevel::Rotors:
      return Command::rotors(std::vector<double>(rotor_command_.begin(), rotor_command_.end()));
    case CommandLevel::Wheels:
      break;  // (refused: a quadrotor has no wheels)
  }
  return {};
}

void TeleKybController::setCommand(const Command& command, const Vec3& position) {
  const CommandLevel previous = level_;
  level_ = command.level;
  switch (command.level) {
    case CommandLevel::Position:
      // the references hold its set-point; it is the one tracked from now on (currentSetpoint
      // says so at once, not only after the next position loop)
      current_ = command.setpoint;
      break;
    case CommandLevel::Velocity:
      // the reference point starts where the vehicle is, and moves on from there while the level holds
      if (previous != CommandLevel::Velocity) velocity_point_ = position;
      command_velocity_ = command.velocity;
      command_yaw_rate_ = command.yaw_rate;
      break;
    case CommandLevel::Attitude:
      attitude_ = overLink({command.roll, command.pitch, command.yaw_rate, command.thrust});
      command_ = toInner(attitude_);
      break;
    case CommandLevel::Rates:
      // (no serial link quantisation: the link carries angles)
      command_.roll_q12 = static_cast<std::int32_t>(std::llround(command.body_rates.x() * 4096.0));
      command_.pitch_q12 = static_cast<std::int32_t>(std::llround(command.body_rates.y() * 4096.0));
      command_.yaw_rate_q12 = static_cast<std::int32_t>(std::llround(command.body_rates.z() * 4096.0));
      command_.thrust_q16 = static_cast<std::int32_t>(std::llround(command.thrust * 65536.0));
      break;
    case CommandLevel::Rotors:
      std::copy(command.rotor_speeds.begin(), command.rotor_speeds.end(), rotor_command_.begin());
      break;
    case CommandLevel::Wheels:
      break;  // (refused before: a quadrotor has no wheels)
  }
  // the position loop's integral starts afresh when it takes over again
  if (previous > CommandLevel::Velocity && level_ <= CommandLevel::Velocity) outer_->reset();
}

AttitudeCommand TeleKybController::overLink(const AttitudeCommand& c) const {
  // the serial link: thrust in 8 bits of m g / 128 (255: 2 m g), angles in whole steps
  return command_link_ ? linkCommand(c, controller_mass_, gravity_, angle_step_) : c;
}

// the position loop: position (motion capture or ground truth) to attitude and thrust
void TeleKybController::outerLoop(double t, FlightInputs& in) {
  current_ = in.reference(t, outer_dt_);
  Pose pose;
  Vec3 velocity;
  in.position(pose, velocity);
  const Vec3 forward = pose.orientation * Vec3::UnitX();
  const double yaw = std::atan2(forward.y(), forward.x());
  const double roll = estimate_.roll_q20 / 1048576.0;
  const double pitch = estimate_.pitch_q20 / 1048576.0;
  if (level_ == CommandLevel::Velocity) {
    // a point moving at the commanded velocity, never more than kVelocityLeash from the vehicle
    // per axis: the velocity error acts through kd, the point's lead through kp and ki
    velocity_point_ += command_velocity_ * outer_dt_;
    velocity_point_ =
        pose.position + (velocity_point_ - pose.position).cwiseMin(kVelocityLeash).cwiseMax(-kVelocityLeash);
    current_ = Setpoint{velocity_point_, command_velocity_, Vec3::Zero(), yaw, command_yaw_rate_};
  }
  attitude_ = outer_->update(outer_dt_, current_, pose.position, velocity, roll, pitch, yaw);
  // a held heading: the yaw error, wrapped to [-pi, pi], adds a yaw rate (the other references
  // command a yaw rate only, as the TeleKyb controller does)
  if (level_ == CommandLevel::Position && in.holdsHeading())
    attitude_.yaw_rate += heading_kp_ * std::remainder(current_.yaw - yaw, 2.0 * std::numbers::pi);
  // the online thrust estimator: the specific force along the body's z axis, from the position
  // source's velocity (motion capture: no accelerometer bias), against what the commanded thrust
  // should give the mass the controller believes; the command is divided by their ratio
  if (thrust_estimator_) {
    const double g = gravity_;
    const double expected = static_cast<double>(command_.thrust_q16) / 65536.0 / controller_mass_;
    if (have_last_velocity_ && expected > 0.2 * g) {
      const Vec3 specific = (velocity - last_velocity_) / outer_dt_ + Vec3(0, 0, g);
      const double along = specific.dot(pose.orientation * Vec3::UnitZ());
      thrust_ratio_ += outer_dt_ / estimator_tau_ * (along / expected - thrust_ratio_);
      thrust_ratio_ = std::clamp(thrust_ratio_, 0.5, 2.0);
    }
    last_velocity_ = velocity;
    have_last_velocity_ = true;
    attitude_.thrust /= thrust_ratio_;
  }
  // handed to the inner loop as integers (over the serial link, if there is one)
  attitude_ = overLink(attitude_);
  command_ = toInner(attitude_);
}

void TeleKybController::step(std::int64_t run, double t, FlightInputs& in, std::span<double> speeds) {
  // the position loop acts at the position and velocity levels; below them the commands go to the
  // inner loop (attitude, rates) or the motors (rotors) as they were set
  if (run % outer_runs_ == 0 && level_ <= CommandLevel::Velocity) outerLoop(t, in);
  // inner loop: IMU counts to motor commands
  if (run % inner_runs_ == 0 && imu_seen_) {
    // the command as it arrives: command_delay late (the queue holds that many inner-loop ticks)
    // (without a delay the command passes straight through: the queue is not touched)
    if (command_queue_.size() > 1) {
      command_queue_[queue_at_] = command_;
      queue_at_ = (queue_at_ + 1) % command_queue_.size();
    }
    const InnerCommand& arrived = command_queue_.size() == 1 ? command_ : command_queue_[queue_at_];
    const InnerOutput out =
        inner_->evaluate(estimate_, imu_->gyroscope_counts, imu_->accelerometer_counts, arrived,
                         level_ == CommandLevel::Rates ? InnerMode::Rates : InnerMode::Attitude);
    estimate_ = out.estimate;
    // (at the rotors level the estimate goes on, the motors take the command's speeds)
    if (level_ != CommandLevel::Rotors)
      for (std::size_t i = 0; i < out.motors; ++i) speeds[i] = inner_->commandToSpeed(out.motor_commands[i]);
  }
  if (level_ == CommandLevel::Rotors) std::copy_n(rotor_command_.begin(), rotor_count_, speeds.begin());
}

void TeleKybController::saveState(StateWriter& out) const {
  out.write(estimate_);
  out.write(outer_->integral());
  out.write(command_);
  out.write(attitude_);
  saveSetpoint(out, current_);
  out.write(imu_seen_);
  out.write(thrust_ratio_);
  // (without a delay the queue is not kept up to date: its one entry is the current command)
  out.write(command_queue_.size() == 1 ? std::vector<InnerCommand>{command_} : command_queue_);
  out.write(static_cast<std::uint64_t>(queue_at_));
  out.write(last_velocity_);
  out.write(have_last_velocity_);
  out.write(level_);
  out.write(command_velocity_);
  out.write(command_yaw_rate_);
  out.write(velocity_point_);
  out.write(std::vector<double>(rotor_command_.begin(), rotor_command_.begin() + static_cast<std::ptrdiff_t>(rotor_count_)));
}

void TeleKybController::loadState(StateReader& in) {
  in.read(estimate_);
  Vec3 integral;
  in.read(integral);
  outer_->setIntegral(integral);
  in.read(command_);
  in.read(attitude_);
  loadSetpoint(in, current_);
  in.read(imu_seen_);
  in.read(thrust_ratio_);
  std::vector<InnerCommand> queue;
  in.read(queue);
  const auto at = static_cast<std::size_t>(in.get<std::uint64_t>());
  if (queue.size() != command_queue_.size() || at >= queue.size())
    throw StateError("quadrotor: the saved command delay does not fit this controller");
  command_queue_ = queue;
  queue_at_ = at;
  in.read(last_velocity_);
  in.read(have_last_velocity_);
  CommandLevel level = CommandLevel::Position;
  in.read(level);
  if (static_cast<std::size_t>(level) >= std::size(kCommandLevels))
    throw StateError("quadrotor: the saved command level is not one (corrupted)");
  level_ = level;
  in.read(command_velocity_);
  in.read(command_yaw_rate_);
  in.read(velocity_point_);
  std::vector<double> rotors;
  in.read(rotors);
  if (rotors.size() != rotor_count_) throw StateError("quadrotor: the saved rotor command does not fit this controller");
  std::copy(rotors.begin(), rotors.end(), rotor_command_.begin());
}

}  // namespace ssx::quadrotor
