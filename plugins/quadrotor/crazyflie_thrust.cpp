// The Crazyflie firmware's thrust model (crazyflie_thrust.hpp).
#include "crazyflie_thrust.hpp"

#include <algorithm>
#include <cmath>

namespace ssx::quadrotor {

double CrazyflieThrustCurve::volts(double newtons) const {
  // bisection on a bracket the curve crosses, then Newton's steps (the slope is positive
  // everywhere for every set above: its derivative's discriminant is negative)
  double lo = 0, hi = 1;
  while (thrust(hi) < newtons && hi < 1e3) hi *= 2;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (thrust(mid) < newtons ? lo : hi) = mid;
  }
  double v = 0.5 * (lo + hi);
  for (int i = 0; i < 3; ++i) {
    const double slope = c[1] + v * (2 * c[2] + 3 * c[3] * v);
    if (slope > 0) v -= (thrust(v) - newtons) / slope;
  }
  return v;
}

double CrazyflieThrustCurve::pwm(double u, double battery_volts) const {
  const double newtons = std::clamp(u, 0.0, 65535.0) / 65535.0 * thrust_max;
  if (newtons < thrust_min || battery_volts < 2.0) return 0;
  return std::min(65535.0, 65535.0 * volts(newtons) / battery_volts);
}

double BatteryFilter::update(double measured, int ticks) {
  for (int i = 0; i < ticks; ++i) v_ += 0.01 * (measured - v_);
  return v_;
}

}  // namespace ssx::quadrotor
