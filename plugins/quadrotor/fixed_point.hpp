#pragma once
// Integer arithmetic as on a flight controller's microcontroller: Q formats, rounding shifts,
// saturation, integer square root and CORDIC trigonometry. Header-only. Every result is an integer
// defined by integer operations; the square root gets that integer from the FPU where it is faster
// and provably the same (isqrtFloor against isqrtFloorBitwise).

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

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

/// floor(sqrt(n)) as a microcontroller without a square-root unit computes it: one result bit per
/// step. The definition isqrtFloor must agree with (tested).
constexpr std::uint64_t isqrtFloorBitwise(std::uint64_t n) {
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

/// floor(sqrt(n)): the same integer as isqrtFloorBitwise. Below 2^52, n is exact as a double and
/// the correctly rounded square root is off by at most one from the integer root, so one
/// correction each way makes it exact, in fewer cycles than 32 dependent steps.
constexpr std::uint64_t isqrtFloor(std::uint64_t n) {
  if (std::is_constant_evaluated() || n >= (std::uint64_t{1} << 52)) return isqrtFloorBitwise(n);
  auto r = static_cast<std::uint64_t>(std::sqrt(static_cast<double>(n)));
  if (r * r > n) --r;
  if ((r + 1) * (r + 1) <= n) ++r;
  return r;
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

/// atan2(y, x) in Q30 radians, (-pi, pi], of L independent pairs at once (their rotations
/// interleaved: L dependency chains the processor overlaps); inputs of any common scale up to 2^40.
template <std::size_t L>
constexpr std::array<std::int64_t, L> atan2Q30(std::array<std::int64_t, L> y, std::array<std::int64_t, L> x) {
  std::array<std::int64_t, L> angle{};
  std::array<bool, L> zero{};
  for (std::size_t k = 0; k < L; ++k) {
    zero[k] = x[k] == 0 && y[k] == 0;
    // rotate into the right half-plane first
    if (x[k] < 0) {
      const std::int64_t t = x[k];
      if (y[k] >= 0) {
        x[k] = y[k];
        y[k] = -t;
        angle[k] = kPiQ30 / 2;
      } else {
        x[k] = -y[k];
        y[k] = t;
        angle[k] = -kPiQ30 / 2;
      }
    }
    // scale up for precision (keeps |x|, |y| < 2^60 for inputs < 2^40)
    x[k] <<= 16;
    y[k] <<= 16;
  }
  for (int i = 0; i < kCordicIterations; ++i) {
    // (unrolled, so that the lanes live in registers rather than in memory)
#pragma GCC unroll 8
    for (std::size_t k = 0; k < L; ++k) {
      // rotate towards y = 0: by +atan(2^-i) when y > 0, else by -atan(2^-i) (branch-free)
      const std::int64_t xs = x[k] >> i, ys = y[k] >> i;
      const std::int64_t neg = y[k] > 0 ? 0 : -1;
      x[k] += conditionalNegate(ys, neg);
      y[k] -= conditionalNegate(xs, neg);
      angle[k] += conditionalNegate(kAtanTable[i], neg);
    }
  }
  // atan2(0, 0) is 0
  for (std::size_t k = 0; k < L; ++k)
    if (zero[k]) angle[k] = 0;
  return angle;
}

/// atan2(y, x) in Q30 radians, (-pi, pi]; inputs of any common scale up to 2^40.
constexpr std::int64_t atan2Q30(std::int64_t y, std::int64_t x) {
  return atan2Q30<1>({y}, {x})[0];
}

/// sin and cos of L angles in Q30 radians (|angle| <= pi), as Q30 values, their rotations interleaved.
template <std::size_t L>
constexpr void sinCosQ30(std::array<std::int64_t, L> angle, std::array<std::int64_t, L>& s,
                         std::array<std::int64_t, L>& c) {
  std::array<bool, L> flip{};
  std::array<std::int64_t, L> x{}, y{};
  for (std::size_t k = 0; k < L; ++k) {
    // bring the angle into [-pi/2, pi/2], remembering a sign flip
    if (angle[k] > kPiQ30 / 2) {
      angle[k] -= kPiQ30;
      flip[k] = true;
    } else if (angle[k] < -kPiQ30 / 2) {
      angle[k] += kPiQ30;
      flip[k] = true;
    }
    x[k] = kCordicGainQ30;
  }
  for (int i = 0; i < kCordicIterations; ++i) {
    // (unrolled, so that the lanes live in registers rather than in memory)
#pragma GCC unroll 8
    for (std::size_t k = 0; k < L; ++k) {
      // rotate towards angle = 0 (branch-free)
      const std::int64_t xs = x[k] >> i, ys = y[k] >> i;
      const std::int64_t neg = angle[k] >= 0 ? 0 : -1;
      x[k] -= conditionalNegate(ys, neg);
      y[k] += conditionalNegate(xs, neg);
      angle[k] -= conditionalNegate(kAtanTable[i], neg);
    }
  }
  for (std::size_t k = 0; k < L; ++k) {
    s[k] = flip[k] ? -y[k] : y[k];
    c[k] = flip[k] ? -x[k] : x[k];
  }
}

/// sin and cos of an angle in Q30 radians (|angle| <= pi), as Q30 values.
constexpr void sinCosQ30(std::int64_t angle, std::int64_t& s, std::int64_t& c) {
  std::array<std::int64_t, 1> s1{}, c1{};
  sinCosQ30<1>({angle}, s1, c1);
  s = s1[0];
  c = c1[0];
}

}  // namespace ssx::quadrotor::fixed
