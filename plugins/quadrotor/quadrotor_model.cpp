#include "quadrotor_model.hpp"

#include <unsupported/Eigen/MatrixFunctions>

#include "fixed_point.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace ssx::quadrotor {

namespace fx = fixed;

// --- allocation and rotors -------------------------------------------------------------------------

Allocation::Allocation(const std::vector<Rotor>& rotors, const RotorParams& p) {
  const auto n = static_cast<Eigen::Index>(rotors.size());
  a_.resize(4, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Rotor& r = rotors[static_cast<std::size_t>(i)];
    a_(0, i) = r.position.y() * p.thrust_coefficient;
    a_(1, i) = -r.position.x() * p.thrust_coefficient;
    a_(2, i) = -r.direction * p.thrust_coefficient * p.moment_constant;
    a_(3, i) = p.thrust_coefficient;
  }
  a_inv_ = a_.completeOrthogonalDecomposition().pseudoInverse();
}

RotorModel::RotorModel(const std::vector<Rotor>& rotors, const RotorParams& params) : count_(rotors.size()) {
  if (rotors.size() > kMaxRotors)
    throw std::invalid_argument("rotor model: at most " + std::to_string(kMaxRotors) + " rotors");
  auto constants = std::make_shared<Constants>();
  std::copy(rotors.begin(), rotors.end(), constants->rotors.begin());
  constants->params = params;
  constants_ = std::move(constants);
  gains_.fill(1.0);
}

void RotorModel::setParams(const RotorParams& params, const RotorModel& nominal) {
  if (params == constants_->params) return;
  if (params == nominal.params()) {
    constants_ = nominal.constants_;
  } else {
    auto constants = std::make_shared<Constants>(*constants_);
    constants->params = params;
    constants_ = std::move(constants);
  }
  alpha_dt_ = -1;  // the motors' filter factors follow the time constants
}

void RotorModel::setSpeeds(std::span<const double> w) {
  if (w.size() != count_)
    throw std::invalid_argument("rotor model: " + std::to_string(w.size()) + " speeds for " + std::to_string(count_) +
                                " rotors");
  std::copy(w.begin(), w.end(), speeds_.begin());
}

void RotorModel::setThrustGains(std::span<const double> gains) {
  if (gains.size() != count_)
    throw std::invalid_argument("rotor model: " + std::to_string(gains.size()) + " thrust gains for " +
                                std::to_string(count_) + " rotors");
  std::copy(gains.begin(), gains.end(), gains_.begin());
}

void RotorModel::step(double dt, std::span<const double> commanded) {
  const RotorParams& params = constants_->params;
  if (dt != alpha_dt_) {  // the filter factors depend only on dt: compute them once
    alpha_dt_ = dt;
    alpha_up_ = std::exp(-dt / params.time_constant_up);
    alpha_down_ = std::exp(-dt / params.time_constant_down);
  }
  for (std::size_t i = 0; i < count_; ++i) {
    const double target = std::clamp(commanded[i], params.min_rotor_speed, params.max_rotor_speed);
    const double alpha = target > speeds_[i] ? alpha_up_ : alpha_down_;
    speeds_[i] = alpha * speeds_[i] + (1.0 - alpha) * target;
  }
}

void Battery::step(double dt, double mechanical_power) {
  const double electrical = std::max(0.0, mechanical_power) / p_.efficiency;
  const double u_oc = openCircuit();
  const double disc = u_oc * u_oc - 4.0 * p_.resistance * electrical;
  // past the pack's largest power the voltage is the one at that power, half the open circuit
  voltage_ = disc > 0 ? 0.5 * (u_oc + std::sqrt(disc)) : 0.5 * u_oc;
  const double current = electrical / voltage_;
  charge_ = std::max(0.0, charge_ - current * dt / (3600.0 * p_.capacity));
}

double downwashForce(double dz, double dxy, double rotor_radius, double c1, double c2, double c3, double min_dz) {
  // the fitted form diverges as dz -> 0 (alpha grows as 1 / dz^2 while the width stays 0.11 m):
  // robots less than min_dz above count as beside this one, not above it
  if (dz < min_dz) return 0.0;
  const double alpha = c1 * std::pow(rotor_radius / (4.0 * dz), 2);
  const double beta = c2 * dz + c3;
  return -alpha * std::exp(-0.5 * std::pow(dxy / beta, 2));
}

DrydenTurbulence::Scales DrydenTurbulence::scales(double height, double w20) {
  const double h = std::clamp(height / 0.3048, 10.0, 1000.0);  // ft
  const double k = 0.177 + 0.000823 * h;
  Scales s;
  s.sigma_w = 0.1 * w20;
  s.sigma_u = s.sigma_v = s.sigma_w / std::pow(k, 0.4);
  s.length_w = h * 0.3048;
  s.length_u = s.length_v = h / std::pow(k, 1.2) * 0.3048;
  return s;
}

double DrydenTurbulence::spectrum(int axis, double omega, const Scales& s, double airspeed) {
  const double sigma = axis == 0 ? s.sigma_u : axis == 1 ? s.sigma_v : s.sigma_w;
  const double length = axis == 0 ? s.length_u : axis == 1 ? s.length_v : s.length_w;
  const double x = length * omega / airspeed;
  if (axis == 0) return sigma * sigma * 2.0 * length / (std::numbers::pi * airspeed) / (1.0 + x * x);
  return sigma * sigma * length / (std::numbers::pi * airspeed) * (1.0 + 3.0 * x * x) / std::pow(1.0 + x * x, 2);
}

namespace {

// x' = A x + B n, n white with intensity 1. The exact discretisation over dt (Van Loan):
// x_k+1 = F x_k + L e_k, L L^T the covariance the noise adds over dt, e_k standard normal.
void discretise(const Eigen::Matrix2d& A, const Eigen::Vector2d& B, double dt, Eigen::Matrix2d& F, Eigen::Matrix2d& L) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  M.topLeftCorner<2, 2>() = -A * dt;
  M.topRightCorner<2, 2>() = B * B.transpose() * dt;
  M.bottomRightCorner<2, 2>() = A.transpose() * dt;
  const Eigen::Matrix4d E = M.exp();
  F = E.bottomRightCorner<2, 2>().transpose();
  Eigen::Matrix2d Q = F * E.topRightCorner<2, 2>();
  Q = 0.5 * (Q + Q.transpose());
  L = Q.llt().matrixL();
}

}  // namespace

Vec3 DrydenTurbulence::step(double dt, const Scales& s, double airspeed, ssx::Random& random) {
  Vec3 out;
  // u: H(s) = K / (1 + T s), K^2 = 2 sigma^2 T (unit-intensity noise), T = L / V
  {
    const double T = s.length_u / airspeed;
    const double a = std::exp(-dt / T);
    // the first-order filter in closed form: its stationary variance is sigma_u^2
    x_[0] = a * x_[0] + s.sigma_u * std::sqrt(1.0 - a * a) * random.normal();
    out[0] = x_[0];
  }
  // v, w: H(s) = K (1 + sqrt(3) T s) / (1 + T s)^2, K^2 = sigma^2 T
  for (int axis = 1; axis <= 2; ++axis) {
    const double sigma = axis == 1 ? s.sigma_v : s.sigma_w;
    const double T = (axis == 1 ? s.length_v : s.length_w) / airspeed;
    Discrete& d = discrete_[static_cast<std::size_t>(axis - 1)];
    if (d.dt != dt || d.T != T) {
      Eigen::Matrix2d A;
      A << 0, 1, -1 / (T * T), -2 / T;
      discretise(A, Eigen::Vector2d(0, 1), dt, d.F, d.L);
      d.dt = dt;
      d.T = T;
    }
    double* x = &x_[static_cast<std::size_t>(1 + 2 * (axis - 1))];
    const double e0 = random.normal(), e1 = random.normal();
    const Eigen::Vector2d next = d.F * Eigen::Vector2d(x[0], x[1]) + d.L * Eigen::Vector2d(e0, e1);
    x[0] = next[0];
    x[1] = next[1];
    const double K = sigma * std::sqrt(T);
    out[axis] = K / (T * T) * (x[0] + std::sqrt(3.0) * T * x[1]);
  }
  return out;
}

double groundEffectGain(double height, double radius) {
  const double h = std::max(height, 0.5 * radius);
  const double r = radius / (4.0 * h);
  return 1.0 / (1.0 - r * r);
}

void RotorModel::wrench(const Vec3& v_body, const Vec3& w_body, Vec3& force, Vec3& torque) const {
  force.setZero();
  torque.setZero();
  double spin = 0.0;  // sum of s_i w_i, for the rotors' angular momentum
  const Vec3 z = Vec3::UnitZ();
  const RotorParams& p = constants_->params;
  for (std::size_t i = 0; i < count_; ++i) {
    const Rotor& r = constants_->rotors[i];
    const double w = speeds_[i];
    const double thrust = p.thrust_coefficient * w * w * gains_[i];
    // thrust and reaction torque
    const Vec3 f = thrust * z;
    torque += r.position.cross(f) + Vec3(0, 0, -r.direction * p.moment_constant * thrust);
    force += f;
    // rotor drag and rolling moment from the air-relative velocity in the rotor plane
    const Vec3 v = v_body + w_body.cross(r.position);
    const Vec3 v_perp = v - v.dot(z) * z;
    const Vec3 drag = -std::abs(w) * p.rotor_drag_coefficient * v_perp;
    force += drag;
    torque += r.position.cross(drag) - std::abs(w) * p.rolling_moment_coefficient * v_perp;
    spin += r.direction * w;
  }
  // turning spinning rotors takes a torque: the body feels -w x h, h = J_r sum(s_i w_i) z
  if (p.rotor_inertia > 0) torque += -w_body.cross(p.rotor_inertia * spin * z);
}

// --- inner loop, fixed point --------------------------------------------------------------------

namespace {

constexpr double kQ12 = 4096.0;
constexpr double kQ16 = 65536.0;
constexpr double kQ20 = 1048576.0;
constexpr double kMaxPitch = 80.0 * std::numbers::pi / 180.0;

std::int64_t toFixed(double v, double scale) { return std::llround(v * scale); }

}  // namespace

bool mixerFitsFixedPoint(const Eigen::MatrixXd& mixer, double max_angular_acceleration, double max_thrust) {
  // mixer coefficients: Q12 for the angular-acceleration columns, Q20 for the thrust column; with
  // alpha in Q12 and thrust in Q16 every product and the sum of four stay below 2^62
  for (Eigen::Index i = 0; i < mixer.rows(); ++i) {
    double sum = 0;
    for (int j = 0; j < 4; ++j)
      sum += std::abs(static_cast<double>(toFixed(mixer(i, j), j < 3 ? kQ12 : kQ20))) *
             (j < 3 ? max_angular_acceleration * kQ12 : max_thrust * kQ16);
    if (!(sum < 4.6e18)) return false;
  }
  return true;
}

InnerLoopFixed::InnerLoopFixed(const InnerLoopParams& p)
    : min_rotor_speed_(p.min_rotor_speed), max_rotor_speed_(p.max_rotor_speed) {
  if (static_cast<std::size_t>(p.mixer.rows()) > kMaxRotors)
    throw std::invalid_argument("inner loop: at most " + std::to_string(kMaxRotors) + " rotors");
  gyro_to_q16_q16 = toFixed(p.gyro_lsb * kQ16, kQ16);
  dt_q24 = toFixed(p.dt, 16777216.0);
  kp_q8 = toFixed(p.attitude_kp, 256.0);
  kd_q8 = toFixed(p.attitude_kd, 256.0);
  kyaw_q8 = toFixed(p.yaw_rate_kp, 256.0);
  max_alpha_q12 = toFixed(p.max_angular_acceleration, kQ12);
  gyro_weight_q15 = toFixed(p.filter_gyro_weight, 32768.0);
  const double g_counts = p.gravity / p.accel_lsb;
  // (saturated: with a fine accelerometer LSB the squares of 1 g can exceed 64 bits; the IMU's
  // at most 2^24 counts keep the measured norm far below that)
  accel_gate_low2 = toFixed(std::min(0.25 * g_counts * g_counts, 4e18), 1.0);
  accel_gate_high2 = toFixed(std::min(2.25 * g_counts * g_counts, 4e18), 1.0);
  if (!mixerFitsFixedPoint(p.mixer, p.max_angular_acceleration, p.max_thrust))
    throw std::invalid_argument("inner loop: the mixer would overflow 64 bits: lower max_angular_acceleration");
  for (Eigen::Index i = 0; i < p.mixer.rows(); ++i) {
    std::array<std::int64_t, 4> row{};
    for (int j = 0; j < 4; ++j) row[static_cast<std::size_t>(j)] = toFixed(p.mixer(i, j), j < 3 ? kQ12 : kQ20);
    mixer_q20[rotor_count++] = row;
  }
  max_thrust_q16 = toFixed(p.max_thrust, kQ16);
  min_speed_q4 = toFixed(p.min_rotor_speed, 16.0);
  max_speed_q4 = toFixed(p.max_rotor_speed, 16.0);
}

double InnerLoopFixed::commandToSpeed(std::uint8_t command) const {
  return min_rotor_speed_ + (max_rotor_speed_ - min_rotor_speed_) * command / 255.0;
}

InnerOutput InnerLoopFixed::step(const std::array<std::int32_t, 3>& gyro, const std::array<std::int32_t, 3>& accel,
                                 const InnerCommand& command, InnerMode mode) {
  InnerOutput out = evaluate(estimate_, gyro, accel, command, mode);
  estimate_ = out.estimate;
  return out;
}

InnerOutput InnerLoopFixed::evaluate(const AttitudeEstimate& prior, const std::array<std::int32_t, 3>& gyro,
                                     const std::array<std::int32_t, 3>& accel, const InnerCommand& command,
                                     InnerMode mode) const {
  InnerOutput out;
  // body rates, Q16 rad/s
  std::int64_t rate[3];
  for (int i = 0; i < 3; ++i) rate[i] = fx::roundShift(gyro[static_cast<std::size_t>(i)] * gyro_to_q16_q16, 16);

  // Euler angle rates from body rates: roll' = p + tan(pitch) (q sin roll + r cos roll),
  // pitch' = q cos roll - r sin roll (Q30 trigonometry, Q16 results)
  // (both angles' rotations in one loop: two independent chains the processor overlaps)
  std::array<std::int64_t, 2> sines{}, cosines{};
  fx::sinCosQ30<2>({std::int64_t{prior.roll_q20} << 10, std::int64_t{prior.pitch_q20} << 10}, sines, cosines);
  const std::int64_t sr = sines[0], cr = cosines[0], sp = sines[1], cp = cosines[1];
  const std::int64_t u = fx::roundShift(rate[1] * sr + rate[2] * cr, 30);       // Q16
  const std::int64_t tan_u = (u * sp + (u * sp >= 0 ? cp / 2 : -cp / 2)) / cp;  // Q16, cp > 0 (|pitch| < 80 deg)
  const std::int64_t roll_rate = rate[0] + tan_u;
  const std::int64_t pitch_rate = fx::roundShift(rate[1] * cr - rate[2] * sr, 30);

  // predict with the gyro, Q16 * Q24 >> 20 = Q20
  std::int64_t roll = prior.roll_q20 + fx::roundShift(roll_rate * dt_q24, 20);
  std::int64_t pitch = prior.pitch_q20 + fx::roundShift(pitch_rate * dt_q24, 20);

  // correct towards the accelerometer's gravity direction when it reads about 1 g
  const std::int64_t ax = accel[0], ay = accel[1], az = accel[2];
  const std::int64_t norm2 = ax * ax + ay * ay + az * az;
  const std::int64_t pi_q20 = fx::roundShift(fx::kPiQ30, 10);
  if (norm2 >= accel_gate_low2 && norm2 <= accel_gate_high2) {
    // roll from (ay, az), pitch from (-ax, |(ay, az)|), both rotations in one loop
    const auto ayz = static_cast<std::int64_t>(fx::isqrtRound(static_cast<std::uint64_t>(ay * ay + az * az)));
    const auto angles = fx::atan2Q30<2>({ay, -ax}, {az, ayz});
    std::int64_t roll_acc = fx::roundShift(angles[0], 10);
    // blend the shorter way round: upside down, +179 deg and -179 deg are 2 deg apart
    if (roll_acc - roll > pi_q20) roll_acc -= 2 * pi_q20;
    if (roll_acc - roll < -pi_q20) roll_acc += 2 * pi_q20;
    const std::int64_t pitch_acc = fx::roundShift(angles[1], 10);
    roll = fx::roundShift(gyro_weight_q15 * roll + (32768 - gyro_weight_q15) * roll_acc, 15);
    pitch = fx::roundShift(gyro_weight_q15 * pitch + (32768 - gyro_weight_q15) * pitch_acc, 15);
  }
  // keep roll in (-pi, pi], pitch within +-80 deg
  if (roll > pi_q20) roll -= 2 * pi_q20;
  if (roll < -pi_q20) roll += 2 * pi_q20;
  const std::int64_t max_pitch = toFixed(kMaxPitch, kQ20);
  pitch = fx::clamp(pitch, -max_pitch, max_pitch);
  out.estimate = {static_cast<std::int32_t>(roll), static_cast<std::int32_t>(pitch)};

  // attitude control: angular accelerations, Q12 rad/s^2, saturated; in rates mode roll and pitch
  // carry body rates p and q, held by the rate gain alone
  std::int64_t alpha_xy[2];
  if (mode == InnerMode::Attitude) {
    const std::int64_t e_roll = command.roll_q12 - fx::roundShift(roll, 8);
    const std::int64_t e_pitch = command.pitch_q12 - fx::roundShift(pitch, 8);
    alpha_xy[0] = fx::roundShift(kp_q8 * e_roll, 8) - fx::roundShift(kd_q8 * rate[0], 12);
    alpha_xy[1] = fx::roundShift(kp_q8 * e_pitch, 8) - fx::roundShift(kd_q8 * rate[1], 12);
  } else {
    alpha_xy[0] = fx::roundShift(kd_q8 * ((std::int64_t{command.roll_q12} << 4) - rate[0]), 12);
    alpha_xy[1] = fx::roundShift(kd_q8 * ((std::int64_t{command.pitch_q12} << 4) - rate[1]), 12);
  }
  const std::int64_t alpha[3] = {
      fx::clamp(alpha_xy[0], -max_alpha_q12, max_alpha_q12), fx::clamp(alpha_xy[1], -max_alpha_q12, max_alpha_q12),
      fx::clamp(fx::roundShift(kyaw_q8 * ((std::int64_t{command.yaw_rate_q12} << 4) - rate[2]), 12), -max_alpha_q12,
                max_alpha_q12)};
  for (int i = 0; i < 3; ++i)
    out.angular_acceleration_q12[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(alpha[i]);

  // mixer: rotor speed squared in Q8, then speed in Q4, then an 8-bit command
  const std::int64_t min2 = min_speed_q4 * min_speed_q4, max2 = max_speed_q4 * max_speed_q4;
  const std::int64_t range = max_speed_q4 - min_speed_q4;
  const std::int64_t thrust = fx::clamp(command.thrust_q16, 0, max_thrust_q16);
  for (std::size_t r = 0; r < rotor_count; ++r) {
    const auto& m = mixer_q20[r];
    std::int64_t w2 = fx::roundShift(m[0] * alpha[0], 16) + fx::roundShift(m[1] * alpha[1], 16) +
                      fx::roundShift(m[2] * alpha[2], 16) + fx::roundShift(m[3] * thrust, 28);
    w2 = fx::clamp(w2, min2, max2);
    const auto w = static_cast<std::int64_t>(fx::isqrtRound(static_cast<std::uint64_t>(w2)));
    const std::int64_t cmd = range > 0 ? ((w - min_speed_q4) * 255 * 2 + range) / (2 * range) : 0;
    out.motor_commands[out.motors++] = static_cast<std::uint8_t>(fx::clamp(cmd, 0, 255));
  }
  return out;
}

// --- inner loop, floating-point reference --------------------------------------------------------

InnerOutput innerLoopFloat(const InnerLoopParams& p, const AttitudeEstimate& prior,
                           const std::array<std::int32_t, 3>& gyro, const std::array<std::int32_t, 3>& accel,
                           const InnerCommand& command, InnerMode mode) {
  InnerOutput out;
  const Vec3 rate = Vec3(gyro[0], gyro[1], gyro[2]) * p.gyro_lsb;
  const double roll0 = prior.roll_q20 / kQ20, pitch0 = prior.pitch_q20 / kQ20;
  const double roll_rate = rate.x() + std::tan(pitch0) * (rate.y() * std::sin(roll0) + rate.z() * std::cos(roll0));
  const double pitch_rate = rate.y() * std::cos(roll0) - rate.z() * std::sin(roll0);
  double roll = roll0 + roll_rate * p.dt;
  double pitch = pitch0 + pitch_rate * p.dt;
  const double ax = accel[0], ay = accel[1], az = accel[2];
  const double g_counts = p.gravity / p.accel_lsb;
  const double norm2 = ax * ax + ay * ay + az * az;
  // the same gate as the integer loop's, rounded as it is
  const double gate_low2 = std::round(std::min(0.25 * g_counts * g_counts, 4e18));
  const double gate_high2 = std::round(std::min(2.25 * g_counts * g_counts, 4e18));
  if (norm2 >= gate_low2 && norm2 <= gate_high2) {
    const double w = p.filter_gyro_weight;
    double roll_acc = std::atan2(ay, az);
    // blend the shorter way round, as the integer loop
    if (roll_acc - roll > std::numbers::pi) roll_acc -= 2 * std::numbers::pi;
    if (roll_acc - roll < -std::numbers::pi) roll_acc += 2 * std::numbers::pi;
    roll = w * roll + (1 - w) * roll_acc;
    pitch = w * pitch + (1 - w) * std::atan2(-ax, std::sqrt(ay * ay + az * az));
  }
  if (roll > std::numbers::pi) roll -= 2 * std::numbers::pi;
  if (roll < -std::numbers::pi) roll += 2 * std::numbers::pi;
  pitch = std::clamp(pitch, -kMaxPitch, kMaxPitch);
  out.estimate = {static_cast<std::int32_t>(std::llround(roll * kQ20)),
                  static_cast<std::int32_t>(std::llround(pitch * kQ20))};

  // the estimate reaches the control law as a Q12 angle, in both implementations
  const double roll_q12 = static_cast<double>(fx::roundShift(out.estimate.roll_q20, 8)) / kQ12;
  const double pitch_q12 = static_cast<double>(fx::roundShift(out.estimate.pitch_q20, 8)) / kQ12;
  const double e_roll = command.roll_q12 / kQ12 - roll_q12;
  const double e_pitch = command.pitch_q12 / kQ12 - pitch_q12;
  const double amax = p.max_angular_acceleration;
  const bool rates = mode == InnerMode::Rates;
  const double ax_raw = rates ? p.attitude_kd * (command.roll_q12 / kQ12 - rate.x())
                              : p.attitude_kp * e_roll - p.attitude_kd * rate.x();
  const double ay_raw = rates ? p.attitude_kd * (command.pitch_q12 / kQ12 - rate.y())
                              : p.attitude_kp * e_pitch - p.attitude_kd * rate.y();
  const Vec3 alpha(std::clamp(ax_raw, -amax, amax), std::clamp(ay_raw, -amax, amax),
                   std::clamp(p.yaw_rate_kp * (command.yaw_rate_q12 / kQ12 - rate.z()), -amax, amax));
  for (int i = 0; i < 3; ++i)
    out.angular_acceleration_q12[static_cast<std::size_t>(i)] =
        static_cast<std::int32_t>(std::llround(alpha[i] * kQ12));
  const double thrust = std::clamp(command.thrust_q16 / kQ16, 0.0, std::llround(p.max_thrust * kQ16) / kQ16);
  const Eigen::Vector4d x(alpha.x(), alpha.y(), alpha.z(), thrust);
  for (Eigen::Index i = 0; i < p.mixer.rows(); ++i) {
    const double w2 =
        std::clamp(p.mixer.row(i).dot(x), p.min_rotor_speed * p.min_rotor_speed, p.max_rotor_speed * p.max_rotor_speed);
    const double range = p.max_rotor_speed - p.min_rotor_speed;
    const double cmd = range > 0 ? std::round(255.0 * (std::sqrt(w2) - p.min_rotor_speed) / range) : 0.0;
    out.motor_commands[out.motors++] = static_cast<std::uint8_t>(std::clamp(cmd, 0.0, 255.0));
  }
  return out;
}

AttitudeCommand linkCommand(AttitudeCommand c, double mass, double gravity, double angle_step) {
  const double unit = mass * gravity / 128.0;
  c.thrust = std::clamp(std::round(c.thrust / unit), 0.0, 255.0) * unit;
  c.roll = std::round(c.roll / angle_step) * angle_step;
  c.pitch = std::round(c.pitch / angle_step) * angle_step;
  return c;
}

// --- outer loop --------------------------------------------------------------------------------

AttitudeCommand PositionController::update(double dt, const Setpoint& ref, const Vec3& position, const Vec3& velocity,
                                           double roll, double pitch, double yaw) {
  const PositionParams& p = params_;
  const Vec3 error = ref.position - position;
  // integral of the position error, clamped per axis
  for (int i = 0; i < 3; ++i)
    if (p.ki[i] > 0) integral_[i] = std::clamp(integral_[i] + error[i] * dt, -p.integral_limit, p.integral_limit);
  const Vec3 a = ref.acceleration + p.kd.cwiseProduct(ref.velocity - velocity) + p.kp.cwiseProduct(error) +
                 p.ki.cwiseProduct(integral_);
  AttitudeCommand c;
  const double tilt = std::max(0.2, std::cos(roll) * std::cos(pitch));
  c.thrust = std::clamp(p.mass * (a.z() + p.gravity) / tilt, p.min_thrust, p.max_thrust);
  const double max_sin = std::sin(p.max_tilt);
  const double sin_roll =
      std::clamp(p.mass / c.thrust * (std::sin(yaw) * a.x() - std::cos(yaw) * a.y()), -max_sin, max_sin);
  c.roll = std::asin(sin_roll);
  const double sin_pitch = std::clamp(
      p.mass / (c.thrust * std::cos(c.roll)) * (std::cos(yaw) * a.x() + std::sin(yaw) * a.y()), -max_sin, max_sin);
  c.pitch = std::asin(sin_pitch);
  c.yaw_rate = ref.yaw_rate;  // rate mode: the feed-forward passes through
  return c;
}

// --- references --------------------------------------------------------------------------------

Setpoint FigureEight::at(double t) const {
  const double w = 2.0 * std::numbers::pi / period;
  const double s = w * t;
  const double a = amplitude;
  // the first axis is x; the second is y (horizontal) or z (vertical)
  const Vec3 along(a * std::sin(s), 0.5 * a * std::sin(2 * s), 0);
  const Vec3 speed(a * w * std::cos(s), a * w * std::cos(2 * s), 0);
  const Vec3 accel(-a * w * w * std::sin(s), -2 * a * w * w * std::sin(2 * s), 0);
  auto place = [this](const Vec3& v) { return vertical ? Vec3(v.x(), 0, v.y()) : v; };
  Setpoint sp;
  sp.position = center + place(along);
  sp.velocity = place(speed);
  sp.acceleration = place(accel);
  sp.yaw = yaw_rate * t;
  sp.yaw_rate = yaw_rate;
  return sp;
}

// --- formation -----------------------------------------------------------------------------------

namespace {
// cot(pi/2 x) for x in (0, 1], saturated near 0
double cotHalfPi(double x) {
  const double a = std::numbers::pi / 2 * std::max(x, 1e-3);
  return std::cos(a) / std::sin(a);
}
}  // namespace

Vec3 Formation::target(std::size_t i) const {
  const double n = static_cast<double>(size);
  const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double theta = static_cast<double>(i) * std::numbers::pi * (3.0 - std::sqrt(5.0));
  return center + radius * Vec3(r * std::cos(theta), r * std::sin(theta), z);
}

double Formation::clearanceGradient(double d) const {
  return d < clearance ? std::min(cotHalfPi(d / clearance), 1.0) : 0.0;
}

double Formation::pairGradient(double d, double d_star) const {
  double g = 0;
  if (d < d_star) {
    g = cotHalfPi(d / d_star);  // 0 at d*, growing without bound towards contact
  } else if (d_star < sensing_range && d < sensing_range) {
    g = -cotHalfPi(1.0 - (d - d_star) / (sensing_range - d_star));  // 0 at d*, growing towards R_s
  }
  return std::clamp(g, -1.0, 1.0);
}

double Formation::obstacleGradient(double d) const {
  if (d >= obstacle_distance) return 0.0;
  const double x = (d - obstacle_saturation) / (obstacle_distance - obstacle_saturation);
  return std::min(cotHalfPi(x), 1.0);
}

}  // namespace ssx::quadrotor
