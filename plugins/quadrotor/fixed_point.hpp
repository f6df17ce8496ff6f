#pragma once
// Integer arithmetic as on a flight controller's microcontroller: Q formats, rounding shifts,
// saturation, integer square root and CORDIC trigonometry. Header-only, no floating point.

#include <cstdint>
#include <limits>

namespace ssx::quadrotor::fixed {

/// Rounding right shift: (a + 2^(b-1)) >> b, rounding half up.
constexpr std::int64_t roundShift(std::int64_t a, int b) {
  return b <= 0 ? a : (a + (std::int64_t{1} << (b - 1))) >> b;
}

constexpr std::int64_t clamp(std::int64_t v, std::int64_t lo, std::int64_t hi) {
  return v < lo ? lo : (v > hi ? hi : v);
}

constexpr std::int32_t saturate32(std::int64_t v) {
  return static_cast<std::int32_t>(
      clamp(v, std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()));
}

/// floor(sqrt(n)).
constexpr std::uint64_t isqrtFloor(std::uint64_t n) {
  std::uint64_t result = 0;
  std::uint64_t bit = std::uint64_t{1} << 62;
  while (bit > n) bit >>= 2;
  while (bit != 0) {
    // branch-free (conditional moves): the outcome of each step is data, not a jump to predict
    const std::uint64_t trial = result + bit;
    const std::uint64_t take = n >= trial ? ~std::uint64_t{0} : 0;
    n -= trial & take;
    result = (result >> 1) + (bit & take);
    bit >>= 2;
  }
  return result;
}

/// sqrt(n) rounded to the nearest integer.
constexpr std::uint64_t isqrtRound(std::uint64_t n) {
  const std::uint64_t r = isqrtFloor(n);
  return (n - r * r > r) ? r + 1 : r;
}

// atan(2^-i) in Q30 radians, i = 0..29
inline constexpr std::int64_t kAtanTable[30] = {
    843314857, 497837829, 263043837, 133525159, 67021687, 33543516, 16775851, 8388437, 4194283, 2097149,
    1048576,   524288,    262144,    131072,    65536,    32768,    16384,    8192,    4096,    2048,
    1024,      512,       256,       128,       64,       32,       16,       8,       4,       2};
inline constexpr std::int64_t kPiQ30 = 3373259426;         // pi * 2^30
inline constexpr std::int64_t kCordicGainQ30 = 652032874;  // prod 1/sqrt(1 + 2^-2i) * 2^30 (i < 24: same to 2^-30)
// 24 rotations leave an angle error below 2^-23 rad, far under the Q20 filter state's resolution
inline constexpr int kCordicIterations = 24;

/// v when mask is 0, -v when mask is -1 (all ones): two's complement without a branch.
constexpr std::int64_t conditionalNegate(std::int64_t v, std::int64_t mask) { return (v ^ mask) - mask; }

/// atan2(y, x) in Q30 radians, (-pi, pi]; inputs of any common scale up to 2^40.
constexpr std::int64_t atan2Q30(std::int64_t y, std::int64_t x) {
  if (x == 0 && y == 0) return 0;
  // rotate into the right half-plane first
  std::int64_t angle = 0;
  if (x < 0) {
    const std::int64_t t = x;
    if (y >= 0) {
      x = y;
      y = -t;
      angle = kPiQ30 / 2;
    } else {
      x = -y;
      y = t;
      angle = -kPiQ30 / 2;
    }
  }
  // scale up for precision (keeps |x|, |y| < 2^60 for inputs < 2^40)
  x <<= 16;
  y <<= 16;
  for (int i = 0; i < kCordicIterations; ++i) {
    // rotate towards y = 0: by +atan(2^-i) when y > 0, else by -atan(2^-i) (branch-free)
    const std::int64_t xs = x >> i, ys = y >> i;
    const std::int64_t neg = y > 0 ? 0 : -1;
    x += conditionalNegate(ys, neg);
    y -= conditionalNegate(xs, neg);
    angle += conditionalNegate(kAtanTable[i], neg);
  }
  return angle;
}

/// sin and cos of an angle in Q30 radians (|angle| <= pi), as Q30 values.
constexpr void sinCosQ30(std::int64_t angle, std::int64_t& s, std::int64_t& c) {
  // bring the angle into [-pi/2, pi/2], remembering a sign flip
  bool flip = false;
  if (angle > kPiQ30 / 2) {
    angle -= kPiQ30;
    flip = true;
  } else if (angle < -kPiQ30 / 2) {
    angle += kPiQ30;
    flip = true;
  }
  std::int64_t x = kCordicGainQ30, y = 0, z = angle;
  for (int i = 0; i < kCordicIterations; ++i) {
    // rotate towards z = 0 (branch-free)
    const std::int64_t xs = x >> i, ys = y >> i;
    const std::int64_t neg = z >= 0 ? 0 : -1;
    x -= conditionalNegate(ys, neg);
    y += conditionalNegate(xs, neg);
    z -= conditionalNegate(kAtanTable[i], neg);
  }
  s = flip ? -y : y;
  c = flip ? -x : x;
}

}  // namespace ssx::quadrotor::fixed
