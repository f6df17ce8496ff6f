#pragma once
// An IMU's counts from a reading in LSB: std::llround, bit for bit, without its call into libm
// (six a step, a fiftieth of a Crazyflie's step).
#include <cmath>
#include <cstdint>

namespace ssx::plugins {

/// std::llround(x) for |x| < 2^62: x's whole part by truncation, then one more away from zero
/// when the part left is a half or more (a - whole is exact: they are within one of each other).
inline std::int64_t roundCounts(double x) {
  const double a = std::fabs(x);
  auto whole = static_cast<std::int64_t>(a);
  if (a - static_cast<double>(whole) >= 0.5) ++whole;
  return x < 0 ? -whole : whole;
}

}  // namespace ssx::plugins
