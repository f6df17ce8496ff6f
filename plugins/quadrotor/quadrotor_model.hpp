#pragma once
// The quadrotor model and flight controller, free of the plugin glue so that tests and programs
// can use each part alone. Reference numbers: docs/quadrotor-reference.md.
//
//   RotorModel      first-order motors, thrust kF w^2, reaction torque, rotor drag, rolling moment
//   Allocation      maps rotor speeds squared to body torques and thrust, and back
//   InnerLoopFixed  integer attitude estimate (complementary filter) + attitude control + 8-bit mixer
//   innerLoopFloat  the same law in double precision: the reference the fixed-point code must match
//   PositionController  the outer loop in floating point (TeleKyb form)
//   FigureEight     reference trajectories of the fidelity study

#include <ssx/descriptor.hpp>
#include <ssx/random.hpp>
#include <ssx/setpoint.hpp>
#include <ssx/state.hpp>
#include <ssx/types.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace ssx::quadrotor {

/// Rotor and motor constants of a vehicle (SI units).
struct RotorParams {
  double thrust_coefficient = 1.0e-5;          ///< kF, N/(rad/s)^2
  double moment_constant = 0.016;              ///< kM, m: reaction torque = kM * thrust
  double time_constant_up = 0.0125;            ///< s
  double time_constant_down = 0.025;           ///< s
  double max_rotor_speed = 940.0;              ///< rad/s
  double min_rotor_speed = 0.0;                ///< rad/s (idle)
  double rotor_drag_coefficient = 8.06428e-5;  ///< lambda1, N/(m/s)/(rad/s)
  double rolling_moment_coefficient = 1e-6;    ///< mu1, N m/(m/s)/(rad/s)
  double rotor_inertia = 0.0;                  ///< kg m^2; > 0 adds the rotors' gyroscopic torque
  double rotor_radius = 0.127;                 ///< m, for ground effect (10-inch propellers; EST)
  bool operator==(const RotorParams&) const = default;
};

/// Ground effect on one rotor (Cheeseman and Bennett 1955, the form gym-pybullet-drones uses):
/// thrust in ground effect / thrust out of it = 1 / (1 - (R / (4 h))^2) for a rotor of radius R
/// at height h above the ground. The formula diverges at h = R/4; heights below R/2 count as R/2
/// (a gain of at most 4/3).
double groundEffectGain(double height, double radius);

/// A battery pack: its open-circuit voltage falls linearly with the charge drawn, an internal
/// resistance sags it under load, and the thrust of a rotor at a fixed command follows the
/// MikroKopter law F proportional to (U - 7.575 V), equal to the model's at the nominal voltage;
/// or, `compensated`, not at all: the flight controller reads the voltage and compensates (the
/// Crazyflie's firmware; its controller then gives the thrust the voltage allows).
/// The defaults are the mk_quad's: EST marks guesses for a 4S 2200 mAh pack (no published figure
/// for the MK's). The presets (examples/presets/quadrotor) give each vehicle's.
struct BatteryParams {
  double full_voltage = 16.8;          ///< V, open circuit when full (4S LiPo, 4.2 V a cell)
  double empty_voltage = 14.0;         ///< V, open circuit when the capacity is drawn (EST, 3.5 V a cell)
  double capacity = 2.2;               ///< Ah (EST)
  double resistance = 0.04;            ///< ohm, internal (EST)
  double efficiency = 0.6;             ///< mechanical / electrical power of motors and controllers (EST)
  double nominal_voltage = 15.5;       ///< V: thrust gain 1 (the MK law's reference)
  double zero_thrust_voltage = 7.575;  ///< V: the MK law's offset
  double initial_charge = 1.0;         ///< fraction of the capacity at the start
  bool compensated = false;            ///< the controller compensates: no thrust law here
};

class Battery {
 public:
  explicit Battery(const BatteryParams& p) : p_(p), charge_(p.initial_charge), voltage_(openCircuit()) {}
  /// Thrust at a fixed command relative to the nominal voltage's: (U - U0) / (U_nom - U0).
  double thrustGain(double voltage) const {
    if (p_.compensated) return 1.0;
    return (voltage - p_.zero_thrust_voltage) / (p_.nominal_voltage - p_.zero_thrust_voltage);
  }
  double thrustGain() const { return thrustGain(voltage_); }
  /// The open-circuit voltage at the charge left (plus the offset a learning environment drew).
  double openCircuit() const {
    return p_.empty_voltage + (p_.full_voltage - p_.empty_voltage) * charge_ + offset_;
  }
  /// Volts added to the open-circuit voltage from the next step on (0: the pack as configured).
  void setOffset(double volts) { offset_ = volts; }
  /// Delivers `mechanical_power` W for dt s: the terminal voltage U solves U = U_oc - R P / (eta U);
  /// the charge drops by the current times dt.
  void step(double dt, double mechanical_power);
  double voltage() const { return voltage_; }
  double charge() const { return charge_; }
  void setState(double charge, double voltage) {
    charge_ = charge;
    voltage_ = voltage;
  }
  const BatteryParams& params() const { return p_; }

 private:
  BatteryParams p_;
  double offset_ = 0;  // (before voltage_, which the constructor sets from openCircuit())
  double charge_, voltage_;
};

/// Downwash on a rotorcraft below another (gym-pybullet-drones' model, fitted on Crazyflies by
/// Zhou at the Dynamic Systems Lab): a vertical force -alpha exp(-(dxy / beta)^2 / 2) with
/// alpha = c1 (R / (4 dz))^2 and beta = c2 dz + c3, for a robot dz above (dz > 0) and dxy apart
/// horizontally. Returns the force's z component (N, negative: down); 0 for dz below `min_dz`,
/// where the form diverges (our cut: a robot that little above is beside this one, or colliding).
/// Fitted on Crazyflies; directly below, it exceeds a Crazyflie's weight for dz under about 0.5 m.
double downwashForce(double dz, double dxy, double rotor_radius, double c1, double c2, double c3, double min_dz);

/// Dryden turbulence (MIL-F-8785C, low altitude): three gust velocities (m/s) in the frame of the
/// mean wind (u along it, v across, w up), each the output of its forming filter driven by white
/// noise, discretised exactly (the sampled process has the continuous one's covariance at every lag).
/// Scales for a height h (ft, 10 to 1000): sigma_w = 0.1 W20, sigma_u = sigma_v = sigma_w /
/// (0.177 + 0.000823 h)^0.4, L_w = h, L_u = L_v = h / (0.177 + 0.000823 h)^1.2; V is the airspeed.
/// One-sided spectra (rad/s): Phi_u = sigma_u^2 (2 L_u / (pi V)) / (1 + (L_u w / V)^2),
/// Phi_v,w = sigma^2 (L / (pi V)) (1 + 3 (L w / V)^2) / (1 + (L w / V)^2)^2.
class DrydenTurbulence {
 public:
  struct Scales {
    double sigma_u, sigma_v, sigma_w;  ///< m/s
    double length_u, length_v, length_w;  ///< m
  };
  /// The scales at `height` m for the wind speed `w20` m/s at 20 ft (6.1 m).
  static Scales scales(double height, double w20);
  /// One-sided spectrum of component `axis` (0 u, 1 v, 2 w) at `omega` rad/s, (m/s)^2 / (rad/s).
  static double spectrum(int axis, double omega, const Scales& s, double airspeed);
  /// Advances the three filters by dt at these scales and airspeed; returns (u, v, w).
  Vec3 step(double dt, const Scales& s, double airspeed, ssx::Random& random);
  /// The filters' state (for save and restore).
  std::array<double, 5> state() const { return x_; }
  void setState(const std::array<double, 5>& x) { x_ = x; }

 private:
  std::array<double, 5> x_{};  // u: 1 state; v, w: 2 each
  // the discretisation of the v and w filters, kept while dt and their time constants stay
  struct Discrete {
    double dt = -1, T = -1;
    Eigen::Matrix2d F, L;
  };
  std::array<Discrete, 2> discrete_{};
};

/// The most rotors the inner loop's mixer drives.
inline constexpr std::size_t kMaxRotors = 8;

/// One rotor: position in the body (centre-of-mass) frame, spin direction (+1 CCW seen from above).
struct Rotor {
  Vec3 position = Vec3::Zero();
  int direction = 1;
};

/// Maps rotor speeds squared to (tau_x, tau_y, tau_z, thrust), body frame, and back.
class Allocation {
 public:
  Allocation(const std::vector<Rotor>& rotors, const RotorParams& params);
  /// 4 x n matrix: column i is [r_y kF, -r_x kF, -s_i kF kM, kF].
  const Eigen::MatrixXd& matrix() const { return a_; }
  /// n x 4 Moore-Penrose pseudo-inverse.
  const Eigen::MatrixXd& inverse() const { return a_inv_; }

 private:
  Eigen::MatrixXd a_, a_inv_;
};

/// First-order motors and the aerodynamic forces of the rotors (at most kMaxRotors). Its state
/// (speeds, gains) is held inline; the rotors' places and constants in one block that copies share:
/// with thousands of robots a step is bound by memory latency, and a swarm's robots of one type
/// then read one copy of them, which stays in the cache, instead of one each.
class RotorModel {
 public:
  RotorModel(const std::vector<Rotor>& rotors, const RotorParams& params);
  /// Advances the motor speeds by dt towards the commanded speeds (clamped to the limits).
  void step(double dt, std::span<const double> commanded);
  std::span<const double> speeds() const { return {speeds_.data(), count_}; }
  /// One speed per rotor (throws std::invalid_argument for another count).
  void setSpeeds(std::span<const double> w);
  /// Force and torque on the body about its centre of mass, body frame, given the body's
  /// velocity and angular velocity in the body frame (air at rest).
  void wrench(const Vec3& velocity_body, const Vec3& angular_velocity_body, Vec3& force, Vec3& torque) const;
  /// Each rotor's thrust (and its reaction torque) at a given speed is multiplied by its gain
  /// (default 1): ground effect, battery voltage, downwash. One gain per rotor.
  void setThrustGains(std::span<const double> gains);
  std::span<const double> thrustGains() const { return {gains_.data(), count_}; }
  std::span<const Rotor> rotors() const { return {constants_->rotors.data(), count_}; }
  std::size_t size() const { return count_; }
  const RotorParams& params() const { return constants_->params; }
  /// From now on its constants are `params`, the rotors' places kept: shared again with
  /// `nominal` (the model it was copied from) when they are nominal's, else its own copy.
  void setParams(const RotorParams& params, const RotorModel& nominal);

 private:
  struct Constants {
    std::array<Rotor, kMaxRotors> rotors{};
    RotorParams params;
  };
  std::shared_ptr<const Constants> constants_;  // shared by copies
  std::array<double, kMaxRotors> speeds_{};
  std::array<double, kMaxRotors> gains_{};
  std::size_t count_ = 0;
  double alpha_dt_ = -1, alpha_up_ = 0, alpha_down_ = 0;  // exp(-dt/tau) for the last dt
};

/// The largest inner-loop gains the driver accepts; the integer code is tested to agree with its
/// float reference and not to overflow up to these.
struct InnerLoopLimits {
  static constexpr double attitude_kp = 5000.0, attitude_kd = 500.0, yaw_rate_kp = 500.0;
  static constexpr double max_angular_acceleration = 5000.0;
};

/// Gains and conversions of the inner loop, in engineering units; InnerLoopFixed converts them to
/// integers once.
struct InnerLoopParams {
  double dt = 0.002;                        ///< s, inner loop period (500 Hz)
  double attitude_kp = 200.0;               ///< 1/s^2
  double attitude_kd = 25.0;                ///< 1/s
  double yaw_rate_kp = 8.0;                 ///< 1/s
  double max_angular_acceleration = 400.0;  ///< rad/s^2, per axis
  double filter_gyro_weight = 0.998;        ///< complementary filter: weight of the gyro path per step
  double gyro_lsb = 6.98131700797732e-4;    ///< rad/s per count
  double accel_lsb = 8.16893945e-3;         ///< m/s^2 per count
  double gravity = 9.81;                    ///< m/s^2, for the accelerometer gate
  Mat3 inertia = Vec3(0.009, 0.009, 0.018).asDiagonal().toDenseMatrix();
  double min_rotor_speed = 0.0, max_rotor_speed = 940.0;
  double max_thrust = 35.0;  ///< N; the thrust command is saturated here (the rotors' total at full speed)
  Eigen::MatrixXd mixer;     ///< n x 4: w^2 from (alpha_x, alpha_y, alpha_z, thrust) = A^+ diag(J, 1)
};

/// What the outer loop hands the inner loop, as integers (as over a serial link).
struct InnerCommand {
  std::int32_t roll_q12 = 0, pitch_q12 = 0;  ///< rad (rates mode: p and q in rad/s), Q12
  std::int32_t yaw_rate_q12 = 0;             ///< rad/s, Q12
  std::int32_t thrust_q16 = 0;               ///< N, Q16
};

/// What the inner loop holds: roll and pitch angles (InnerCommand's roll and pitch in rad), or body
/// rates (its roll and pitch carry p and q in rad/s, held by the rate gain attitude_kd). The yaw
/// rate and the thrust mean the same in both.
enum class InnerMode : std::uint8_t { Attitude, Rates };

/// The integer attitude estimate the inner loop keeps.
struct AttitudeEstimate {
  std::int32_t roll_q20 = 0, pitch_q20 = 0;  ///< rad, Q20
};

/// Result of one inner-loop step.
struct InnerOutput {
  AttitudeEstimate estimate;
  std::array<std::int32_t, 3> angular_acceleration_q12{};  ///< rad/s^2, Q12, after saturation
  std::array<std::uint8_t, 8> motor_commands{};            ///< 0..255 per rotor (the first `motors`)
  std::size_t motors = 0;
};

/// The inner loop as it would run on a 32-bit microcontroller: integers only, every product in
/// int64 followed by a rounding shift, every stage saturated. Formats: angles Q20 in the filter
/// state and Q12 at the control law, body rates Q16, gains Q8, angular accelerations Q12, thrust
/// Q16, rotor speed squared Q8, rotor speed Q4, motor commands 8 bits.
/// Whether InnerLoopFixed holds this mixer (InnerLoopParams::mixer) in 64 bits with angular
/// accelerations up to `max_angular_acceleration` and thrust up to `max_thrust` (its constructor
/// throws otherwise).
bool mixerFitsFixedPoint(const Eigen::MatrixXd& mixer, double max_angular_acceleration, double max_thrust);

class InnerLoopFixed {
 public:
  explicit InnerLoopFixed(const InnerLoopParams& params);
  /// One step from raw IMU counts; updates and returns the estimate.
  InnerOutput step(const std::array<std::int32_t, 3>& gyro_counts, const std::array<std::int32_t, 3>& accel_counts,
                   const InnerCommand& command, InnerMode mode = InnerMode::Attitude);
  /// The same step from a given estimate, without touching the loop's own state.
  InnerOutput evaluate(const AttitudeEstimate& prior, const std::array<std::int32_t, 3>& gyro_counts,
                       const std::array<std::int32_t, 3>& accel_counts, const InnerCommand& command,
                       InnerMode mode = InnerMode::Attitude) const;
  const AttitudeEstimate& estimate() const { return estimate_; }
  void reset(const AttitudeEstimate& e) { estimate_ = e; }
  /// Motor command to commanded rotor speed (linear between the speed limits).
  double commandToSpeed(std::uint8_t command) const;

  // integer parameters, public for the tests that check their range
  std::int64_t gyro_to_q16_q16 = 0;  ///< counts -> rad/s Q16, as a Q16 multiplier
  std::int64_t dt_q24 = 0;
  std::int64_t kp_q8 = 0, kd_q8 = 0, kyaw_q8 = 0;
  std::int64_t max_alpha_q12 = 0;
  std::int64_t gyro_weight_q15 = 0;
  std::int64_t accel_gate_low2 = 0, accel_gate_high2 = 0;  ///< counts^2
  std::array<std::array<std::int64_t, 4>, kMaxRotors> mixer_q20{};  ///< alpha columns Q12, thrust column Q20
  std::size_t rotor_count = 0;                                     ///< rows of mixer_q20 in use
  std::int64_t min_speed_q4 = 0, max_speed_q4 = 0;
  std::int64_t max_thrust_q16 = 0;

 private:
  // (only what a step needs, held inline; see RotorModel)
  double min_rotor_speed_ = 0, max_rotor_speed_ = 0;
  AttitudeEstimate estimate_;
};

/// The reference: the same step in double precision, rounded only where the fixed-point code hands
/// a value on (the estimate to Q20, the motor commands to integers).
InnerOutput innerLoopFloat(const InnerLoopParams& params, const AttitudeEstimate& prior,
                           const std::array<std::int32_t, 3>& gyro_counts,
                           const std::array<std::int32_t, 3>& accel_counts, const InnerCommand& command,
                           InnerMode mode = InnerMode::Attitude);

/// A parameter's value if it was given, else nothing (for defaults worked out from others).
template <class T>
std::optional<T> given(const Descriptor& params, const char* key) {
  return params.has(key) ? std::optional<T>(params.get<T>(key)) : std::nullopt;
}

/// A set-point into and out of a saved state (the parts that keep one: controller, references).
inline void saveSetpoint(StateWriter& out, const Setpoint& s) {
  out.write(s.position);
  out.write(s.velocity);
  out.write(s.acceleration);
  out.write(s.yaw);
  out.write(s.yaw_rate);
}
inline void loadSetpoint(StateReader& in, Setpoint& s) {
  in.read(s.position);
  in.read(s.velocity);
  in.read(s.acceleration);
  in.read(s.yaw);
  in.read(s.yaw_rate);
}

/// Outer loop gains and limits.
struct PositionParams {
  double mass = 0.82;  ///< kg, as the controller believes it
  double gravity = 9.81;
  Vec3 kp{9.0, 9.0, 9.0};                      ///< 1/s^2
  Vec3 kd{7.5, 7.5, 7.5};                      ///< 1/s
  Vec3 ki{4.5, 4.5, 0.0};                      ///< 1/s^3
  double integral_limit = 2.0;                 ///< m s, per axis
  double max_tilt = 0.5235987755982988;        ///< rad (30 deg)
  double min_thrust = 0.5, max_thrust = 30.0;  ///< N
};

/// Attitude and thrust set-points for the inner loop.
struct AttitudeCommand {
  double roll = 0, pitch = 0, yaw_rate = 0, thrust = 0;
};

/// A command as the MK serial link carries it: thrust in 8 bits of `mass` g / 128 (so 255 is about
/// 2 m g), roll and pitch rounded to whole `angle_step`s (rad); the yaw rate passes.
AttitudeCommand linkCommand(AttitudeCommand c, double mass, double gravity, double angle_step);

/// The outer loop: position and velocity errors to thrust and attitude (ENU, z up).
class PositionController {
 public:
  explicit PositionController(const PositionParams& params) : params_(params) {}
  /// `yaw`, `roll`, `pitch`: the current attitude (roll and pitch from the inner loop's estimate).
  AttitudeCommand update(double dt, const Setpoint& ref, const Vec3& position, const Vec3& velocity, double roll,
                         double pitch, double yaw);
  void reset() { integral_.setZero(); }
  /// The integral term's state (for saving and restoring).
  const Vec3& integral() const { return integral_; }
  void setIntegral(const Vec3& integral) { integral_ = integral; }

 private:
  PositionParams params_;
  Vec3 integral_ = Vec3::Zero();
};

/// The fidelity study's figure eight: s = w t; horizontal c + (A sin s, A/2 sin 2s, 0), vertical the
/// same curve in the x-z plane; constant yaw rate.
struct FigureEight {
  Vec3 center{0, 0, 1.5};
  double amplitude = 1.0;  ///< A, m
  double period = 12.0;    ///< T, s
  double yaw_rate = 0.2;   ///< rad/s
  bool vertical = false;
  Setpoint at(double t) const;
};

/// Formation control on a sphere (spec section 6): Fibonacci-sphere targets, and a velocity
/// reference from C1 cotangent-shaped potentials over the neighbours a range sensor reports.
struct Formation {
  std::size_t size = 70;             ///< N
  double radius = 4.0;               ///< R, m
  Vec3 center{0, 0, 5};              ///< m
  double sensing_range = 2.5;        ///< R_s, m: neighbours beyond it are not attracted
  double clearance = 1.4;            ///< m: any two robots closer than this repel (below the sphere's 1.48 m spacing)
  double gain = 0.2;                 ///< m/s per unit of the shape potentials' gradient
  double max_speed = 1.0;            ///< m/s, of the virtual point
  double anchor_gain = 0.5;          ///< 1/s, pull towards the robot's own target (v_cmd)
  double obstacle_distance = 0.5;    ///< m: obstacles repel inside it
  double obstacle_saturation = 0.2;  ///< m: the repulsion is saturated inside it

  /// Target of member i: z_i = 1 - 2 (i + 0.5) / N, r_i = sqrt(1 - z_i^2), theta_i = i pi (3 - sqrt 5).
  Vec3 target(std::size_t i) const;
  /// Gradient between two members at distance d whose desired distance is d_star, in [-1, 1]:
  /// > 0 pushes apart (d < d*), < 0 pulls together (d* < d < R_s), 0 at d = d*, C1 there.
  double pairGradient(double d, double d_star) const;
  /// Repulsion between any two robots at distance d, in [0, 1]: 0 beyond `clearance`.
  double clearanceGradient(double d) const;
  /// Repulsion from an obstacle at distance d, in [0, 1]: 0 beyond obstacle_distance, 1 inside
  /// obstacle_saturation.
  double obstacleGradient(double d) const;
};

}  // namespace ssx::quadrotor
