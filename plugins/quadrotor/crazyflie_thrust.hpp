#pragma once
// The Crazyflie firmware's thrust model (crazyflie-firmware 2025.12.1: stabilizer.c
// batteryCompensation(), motors.c motorsCompensateBatteryVoltage(), the coefficients of
// platform_defaults_cf2.h; battery compensation is on by default for the CF2): a motor command u of 0-65535 asks for the thrust u/65535 * thrust_max per
// motor; the motor voltage that gives it is read off the propeller's cubic thrust-voltage curve,
// and the PWM is that voltage over the (low-passed) battery voltage. So a command means newtons
// whatever the battery's charge, until the battery cannot give the voltage (PWM 65535).
#include <array>

namespace ssx::quadrotor {

struct CrazyflieThrustCurve {
  std::array<double, 4> c;  ///< thrust per motor (N) = c0 + c1 V + c2 V^2 + c3 V^3, V the motor voltage
  double thrust_min;        ///< N: below it the motor is off
  double thrust_max;        ///< N: what command 65535 asks for
  double thrust_to_torque;  ///< m: reaction torque per newton of thrust

  /// The firmware's default set since 2025.12 ("2.1+ propellers", platform_defaults_cf2.h).
  static CrazyflieThrustCurve propellers21plus() {
    return {{-0.024765, 0.065238, -0.026793, 0.0067768}, 0.012818, 0.12, 0.0069929};
  }
  /// The set for the older ("legacy") propellers.
  static CrazyflieThrustCurve legacyPropellers() {
    return {{-0.014831, 0.047245, -0.018474, 0.0059609}, 0.012818, 0.12, 0.0073509};
  }

  /// Thrust per motor (N) at motor voltage `volts`.
  double thrust(double volts) const { return c[0] + volts * (c[1] + volts * (c[2] + volts * c[3])); }
  /// The motor voltage that gives `newtons` (the curve rises everywhere: one root), to 1e-12 V.
  double volts(double newtons) const;
  /// The PWM (0-65535, a real number as the firmware's float) for command `u` (0-65535) at the
  /// filtered battery voltage `battery_volts`: 0 below thrust_min or below 2 V, at most 65535.
  double pwm(double u, double battery_volts) const;
  /// The PWM the firmware's compensation (motorsCompensateBatteryVoltage) makes of a motor's
  /// command `u` before the cap: u is not capped at 65535 (the mixer's sums are not) and neither is
  /// the PWM; 0 below thrust_min or below 2 V. The firmware caps the four PWMs together afterwards
  /// (powerDistributionCap).
  double uncappedPwm(double u, double battery_volts) const;
  /// The thrust per motor (N) for command `u` when the motors get the voltage the compensation
  /// reads, `battery_volts`: thrust(pwm(u, V) / 65535 V), which is the thrust asked for up to the
  /// whole battery's, thrust(V); computed so, without inverting the curve.
  double delivered(double u, double battery_volts) const;
};

/// The firmware's low-pass of the battery voltage: every 1 ms tick, v += 0.01 (measured - v),
/// from 4.2 V.
class BatteryFilter {
 public:
  /// Advances by `ticks` ms with the measured voltage `measured`; returns the filtered one.
  double update(double measured, int ticks = 1);
  double volts() const { return v_; }
  /// Holds `volts` (a battery measured long enough).
  void reset(double volts) { v_ = volts; }

 private:
  double v_ = 4.2;
};

}  // namespace ssx::quadrotor
