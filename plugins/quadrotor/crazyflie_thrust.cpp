// The Crazyflie firmware's thrust model (crazyflie_thrust.hpp).
#include "crazyflie_thrust.hpp"

#include <algorithm>
#include <cmath>

namespace ssx::quadrotor {

double CrazyflieThrustCurve::volts(double newtons) const {
  // Newton's method kept inside a bracket the curve crosses (a step that would leave it bisects
  // instead): the slope is positive everywhere for every set above (its derivative's discriminant
  // is negative), so the bracket always holds the one root. From a guess that takes the thrust as
  // growing with the voltage squared, about five steps, where bisection alone took sixty (half a
  // Crazyflie's step went there).
  double lo = 0, hi = 4.5;
  while (thrust(hi) < newtons && hi < 1e3) hi *= 2;
  const double f_lo = thrust(lo) - newtons, f_hi = thrust(hi) - newtons;
  if (f_lo >= 0) return lo;
  double v = lo + (hi - lo) * std::sqrt(-f_lo / (f_hi - f_lo));
  for (int i = 0; i < 100; ++i) {
    const double f = thrust(v) - newtons;
    if (f == 0) return v;
    (f < 0 ? lo : hi) = v;
    const double slope = c[1] + v * (2 * c[2] + 3 * c[3] * v);
    const double step = f / slope, next = v - step;
    if (std::abs(step) <= 1e-13 * (1 + v)) return next >= lo && next <= hi ? next : v;  // converged
    v = next > lo && next < hi ? next : 0.5 * (lo + hi);
  }
  return v;
}

double CrazyflieThrustCurve::pwm(double u, double battery_volts) const {
  const double newtons = std::clamp(u, 0.0, 65535.0) / 65535.0 * thrust_max;
  if (newtons < thrust_min || battery_volts < 2.0) return 0;
  return std::min(65535.0, 65535.0 * volts(newtons) / battery_volts);
}

double CrazyflieThrustCurve::uncappedPwm(double u, double battery_volts) const {
  const double newtons = std::max(u, 0.0) / 65535.0 * thrust_max;
  if (newtons < thrust_min || battery_volts < 2.0) return 0;
  return 65535.0 * volts(newtons) / battery_volts;
}

double CrazyflieThrustCurve::delivered(double u, double battery_volts) const {
  const double newtons = std::clamp(u, 0.0, 65535.0) / 65535.0 * thrust_max;
  if (newtons < thrust_min || battery_volts < 2.0) return 0;
  return std::max(0.0, std::min(newtons, thrust(battery_volts)));
}

double BatteryFilter::update(double measured, int ticks) {
  for (int i = 0; i < ticks; ++i) v_ += 0.01 * (measured - v_);
  return v_;
}

}  // namespace ssx::quadrotor
