#pragma once
// The Crazyflie firmware's extended Kalman filter (crazyflie-firmware 2025.12.1: kalman_core.c and
// estimator_kalman.c; Mueller, Hamer and D'Andrea, ICRA 2015, and Mueller, Hehn and D'Andrea, JGCD
// 2016), written from their description, as the firmware runs it with motion capture:
// - nine error states: position (world), velocity (body frame) and a small attitude error, beside
//   the attitude as a quaternion; the covariance pushed through the dynamics linearised about the
//   estimate;
// - the prediction at 100 Hz from the IMU's samples averaged since the last one; in flight only the
//   accelerometer's body z is used (thrust can push only along it; horizontal drag is not modelled),
//   on the ground all three axes; the attitude turned by the gyroscope;
// - process noise at every run of the loop (acceleration 0.5 m/s^2 horizontally and 1.0 vertically,
//   the gyroscope's 0.1 rad/s on the attitude);
// - each motion-capture position as three scalar updates (standard deviation 0.01 m, the client's
//   default for external positions); the covariance kept symmetric within [1e-6, 100];
// - after the updates, the attitude error moved into the quaternion and the covariance turned with it.
// In double precision (the firmware's floats differ in the last bits).
#include <ssx/state.hpp>
#include <ssx/types.hpp>

#include <Eigen/Core>

namespace ssx::quadrotor {

/// The filter's noise settings (kalmanCoreDefaultParams; the position's: extPosStdDev).
struct CrazyflieKalmanParams {
  double acc_noise_xy = 0.5;    ///< m/s^2: procNoiseAcc_xy
  double acc_noise_z = 1.0;     ///< m/s^2: procNoiseAcc_z
  double gyro_noise_rp = 0.1;   ///< rad/s: measNoiseGyro_rollpitch
  double gyro_noise_yaw = 0.1;  ///< rad/s: measNoiseGyro_yaw
  double position_std = 0.01;   ///< m: a motion-capture position's standard deviation
  double initial_position_std_xy = 100, initial_position_std_z = 1;  ///< m
  double initial_velocity_std = 0.01;                                ///< m/s
  double initial_attitude_std = 0.01;                                ///< rad
  double attitude_reversion = 0.001;  ///< per prediction on the ground: the attitude drawn back to level
};

/// The filter: reset, then per run of the controller addImu, predict when due, addProcessNoise,
/// updatePosition for a new position, finalize.
class CrazyflieKalman {
 public:
  explicit CrazyflieKalman(const CrazyflieKalmanParams& params = {});

  /// Starts again at `position` (m, world) facing `yaw` (rad), level and at rest, with the
  /// firmware's initial variances.
  void reset(const Vec3& position, double yaw);
  /// One IMU sample: specific force (m/s^2) and angular rate (rad/s), body frame.
  void addImu(const Vec3& accelerometer, const Vec3& gyroscope);
  /// The prediction over `dt` seconds with the samples' means since the last one (none: nothing);
  /// `flying`: the motors run (the accelerometer's body z only).
  void predict(double dt, bool flying);
  /// Process noise for `dt` seconds.
  void addProcessNoise(double dt);
  /// A measured position (m, world).
  void updatePosition(const Vec3& measured);
  /// Moves the attitude error into the attitude (after updates; nothing without one).
  void finalize();

  /// Position (m, world).
  Vec3 position() const { return s_.head<3>(); }
  /// Velocity, world frame (the body-frame state turned by the attitude).
  Vec3 velocity() const;
  /// Attitude, body to world.
  Quat attitude() const { return q_; }
  /// The covariance's diagonal (x, y, z, body velocity, attitude error).
  Eigen::Matrix<double, 9, 1> variances() const { return P_.diagonal(); }

  /// Appends the filter's state.
  void save(StateWriter& out) const;
  /// Reads a state save() wrote; StateError for one that is not finite.
  void load(StateReader& in);

 private:
  using Vec9 = Eigen::Matrix<double, 9, 1>;
  using Mat9 = Eigen::Matrix<double, 9, 9>;
  void scalarUpdate(int index, double error, double std);
  void bound();  // symmetric, diagonal at least 1e-6, every entry at most 100

  CrazyflieKalmanParams p_;
  Vec9 s_ = Vec9::Zero();  // x y z, body velocity, attitude error
  Mat9 P_ = Mat9::Zero();
  Quat q_ = Quat::Identity(), initial_ = Quat::Identity();
  Mat3 R_ = Mat3::Identity();  // the attitude as a matrix, body to world (from the last finalize)
  Vec3 acc_sum_ = Vec3::Zero(), gyro_sum_ = Vec3::Zero();
  int samples_ = 0;
  bool updated_ = false;
};

}  // namespace ssx::quadrotor
