// The Crazyflie firmware's extended Kalman filter (crazyflie_kalman.hpp).
#include "crazyflie_kalman.hpp"

#include <ssx/error.hpp>

#include <cmath>

namespace ssx::quadrotor {

namespace {

constexpr double kGravity = 9.81;  // the firmware's GRAVITY_MAGNITUDE
constexpr double kMaxCovariance = 100, kMinCovariance = 1e-6;
enum : int { X = 0, PX = 3, D0 = 6 };  // the first of each group of three states

// The covariance turned by a small rotation d (half the angle, about each axis): the second-order
// approximation of exp(-[d]) as the firmware writes it, for the attitude error's block.
Mat3 attitudeTurn(const Vec3& d) {
  Mat3 a;
  a << 1 - d.y() * d.y() / 2 - d.z() * d.z() / 2, d.z() + d.x() * d.y() / 2, -d.y() + d.x() * d.z() / 2,
      -d.z() + d.x() * d.y() / 2, 1 - d.x() * d.x() / 2 - d.z() * d.z() / 2, d.x() + d.y() * d.z() / 2,
      d.y() + d.x() * d.z() / 2, -d.x() + d.y() * d.z() / 2, 1 - d.x() * d.x() / 2 - d.y() * d.y() / 2;
  return a;
}

// the matrix of v's cross product: crossMatrix(v) w = v x w
Mat3 crossMatrix(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// a quaternion scaled to unit length as the firmware does (its EPS in the norm)
Quat unitLength(const Quat& q) { return Quat(q.coeffs() / (q.coeffs().norm() + 1e-6)); }

// the quaternion turned in its own frame by the rotation vector v (rad)
Quat turned(const Quat& q, const Vec3& v) {
  const double angle = v.norm() + 1e-6;  // the firmware's EPS keeps a zero rotation finite
  const double s = std::sin(angle / 2);
  const Quat dq(std::cos(angle / 2), s * v.x() / angle, s * v.y() / angle, s * v.z() / angle);
  return q * dq;
}

}  // namespace

CrazyflieKalman::CrazyflieKalman(const CrazyflieKalmanParams& params) : p_(params) { reset(Vec3::Zero(), 0); }

void CrazyflieKalman::reset(const Vec3& position, double yaw) {
  s_.setZero();
  s_.head<3>() = position;
  initial_ = Quat(std::cos(yaw / 2), 0, 0, std::sin(yaw / 2));
  q_ = initial_;
  R_ = q_.toRotationMatrix();
  P_.setZero();
  const double xy = p_.initial_position_std_xy, z = p_.initial_position_std_z, v = p_.initial_velocity_std,
               a = p_.initial_attitude_std;
  const double diagonal[9] = {xy * xy, xy * xy, z * z, v * v, v * v, v * v, a * a, a * a, a * a};
  for (int i = 0; i < 9; ++i) P_(i, i) = diagonal[i];
  acc_sum_.setZero();
  gyro_sum_.setZero();
  samples_ = 0;
  updated_ = false;
}

void CrazyflieKalman::addImu(const Vec3& accelerometer, const Vec3& gyroscope) {
  acc_sum_ += accelerometer;
  gyro_sum_ += gyroscope;
  ++samples_;
}

void CrazyflieKalman::predict(double dt, bool flying) {
  if (samples_ == 0) return;
  const Vec3 acc = acc_sum_ / samples_, gyro = gyro_sum_ / samples_;
  acc_sum_.setZero();
  gyro_sum_.setZero();
  samples_ = 0;

  // the dynamics linearised about the estimate: x' = R p, p' = f e3 - w x p - g R^T e3, d' = w
  const Vec3 p = s_.segment<3>(PX);
  Mat9 A = Mat9::Identity();
  A.block<3, 3>(X, PX) = R_ * dt;
  // position from the attitude error: R [p]x^T, i.e. -R [p]x
  A.block<3, 3>(X, D0) = -R_ * crossMatrix(p) * dt;
  // body velocity from body velocity (no drag): the gyroscope's cross product
  A.block<3, 3>(PX, PX) = Mat3::Identity() - crossMatrix(gyro) * dt;
  // body velocity from the attitude error: gravity seen in the body frame turning
  const Vec3 g_body = R_.row(2).transpose();  // the world's z in the body frame
  A.block<3, 3>(PX, D0) = -kGravity * crossMatrix(g_body) * dt;
  A.block<3, 3>(D0, D0) = attitudeTurn(gyro * dt / 2);
  P_ = A * P_ * A.transpose();

  // the state: in flight only the thrust's axis is measured, on the ground the whole accelerometer
  const Vec3 f = flying ? Vec3(0, 0, acc.z()) : acc;
  const Vec3 dp = p * dt + f * dt * dt / 2;
  s_.head<3>() += R_ * dp - Vec3(0, 0, kGravity * dt * dt / 2);
  s_.segment<3>(PX) = p + dt * (f - gyro.cross(p) - kGravity * g_body);

  Quat q = turned(q_, gyro * dt);
  if (!flying) {  // on the ground the attitude is drawn back to level, slowly
    const double keep = 1 - p_.attitude_reversion;
    q.coeffs() = keep * q.coeffs() + p_.attitude_reversion * initial_.coeffs();
  }
  q_ = unitLength(q);
  updated_ = true;
}

void CrazyflieKalman::addProcessNoise(double dt) {
  const double pos_xy = p_.acc_noise_xy * dt * dt, pos_z = p_.acc_noise_z * dt * dt;
  const double vel_xy = p_.acc_noise_xy * dt, vel_z = p_.acc_noise_z * dt;
  const double att_rp = p_.gyro_noise_rp * dt, att_yaw = p_.gyro_noise_yaw * dt;
  const double add[9] = {pos_xy * pos_xy, pos_xy * pos_xy, pos_z * pos_z,   vel_xy * vel_xy,  vel_xy * vel_xy,
                         vel_z * vel_z,   att_rp * att_rp, att_rp * att_rp, att_yaw * att_yaw};
  for (int i = 0; i < 9; ++i) P_(i, i) += add[i];
  bound();
}

void CrazyflieKalman::scalarUpdate(int index, double error, double std) {
  const double r = std * std;
  const Vec9 ph = P_.col(index);  // P H^T for H = e_index
  const double hphr = ph(index) + r;
  const Vec9 k = ph / hphr;
  s_ += k * error;
  Mat9 kh_i = -Mat9::Identity();
  kh_i.col(index) += k;
  P_ = kh_i * P_ * kh_i.transpose() + k * r * k.transpose();
  bound();
  updated_ = true;
}

void CrazyflieKalman::updatePosition(const Vec3& measured) {
  for (int i = 0; i < 3; ++i) scalarUpdate(X + i, measured[i] - s_[X + i], p_.position_std);
}

void CrazyflieKalman::finalize() {
  if (!updated_) return;
  const Vec3 v = s_.segment<3>(D0);
  if (const double largest = v.cwiseAbs().maxCoeff(); largest > 0.1e-3 && largest < 10) {
    q_ = unitLength(turned(q_, v));
    Mat9 A = Mat9::Identity();
    A.block<3, 3>(D0, D0) = attitudeTurn(v / 2);
    P_ = A * P_ * A.transpose();
  }
  R_ = q_.toRotationMatrix();
  s_.segment<3>(D0).setZero();
  bound();
  updated_ = false;
}

Vec3 CrazyflieKalman::velocity() const { return R_ * s_.segment<3>(PX); }

void CrazyflieKalman::bound() {
  for (int i = 0; i < 9; ++i)
    for (int j = i; j < 9; ++j) {
      const double v = 0.5 * P_(i, j) + 0.5 * P_(j, i);
      double b = v;
      if (std::isnan(v) || v > kMaxCovariance)
        b = kMaxCovariance;
      else if (i == j && v < kMinCovariance)
        b = kMinCovariance;
      P_(i, j) = P_(j, i) = b;
    }
}

void CrazyflieKalman::save(StateWriter& out) const {
  for (int i = 0; i < 9; ++i) out.write(s_[i]);
  for (int i = 0; i < 81; ++i) out.write(P_.data()[i]);
  out.write(q_);
  out.write(initial_);
  out.write(acc_sum_);
  out.write(gyro_sum_);
  out.write(static_cast<std::int32_t>(samples_));
  out.write(updated_);
}

void CrazyflieKalman::load(StateReader& in) {
  for (int i = 0; i < 9; ++i) in.read(s_[i]);
  for (int i = 0; i < 81; ++i) in.read(P_.data()[i]);
  in.read(q_);
  in.read(initial_);
  in.read(acc_sum_);
  in.read(gyro_sum_);
  std::int32_t samples = 0;
  in.read(samples);
  if (samples < 0) throw StateError("crazyflie estimator: a negative count of IMU samples in the saved state");
  samples_ = samples;
  in.read(updated_);
  if (!s_.allFinite() || !P_.allFinite() || !q_.coeffs().allFinite())
    throw StateError("crazyflie estimator: a saved state that is not finite");
  R_ = q_.toRotationMatrix();
}

}  // namespace ssx::quadrotor
