#pragma once
/// @file
/// Random streams that give the same numbers on every platform and thread count.

#include <ssx/export.hpp>

#include <cstdint>
#include <optional>
#include <string_view>

namespace ssx {

class StateWriter;
class StateReader;

/// Seeds are whole numbers from 0 to 2^64 - 1 everywhere one is given (scene `seed`, `ssx run
/// --seed`, Python's `seed=`, sweep files, and the runs a sweep derives).
inline constexpr std::uint64_t kMaxSeed = 18'446'744'073'709'551'615ULL;

/// A seed written in decimal (digits only: no sign, no hex, no exponent, nothing after), or
/// nothing when the text is not one or is beyond kMaxSeed.
SSX_EXPORT std::optional<std::uint64_t> parseSeed(std::string_view text);

/// Mixes a seed with stream indices into an independent 64-bit seed (SplitMix64 finaliser).
/// Every stream in ssx is derived from (scene seed, artifact index, plugin index).
SSX_EXPORT std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0);

/// A small, fast generator (xoshiro256++) with its own distributions, written here so that the
/// numbers do not depend on the standard library's implementation. Not thread-safe: one stream
/// belongs to one plugin instance.
class SSX_EXPORT Random {
 public:
  using result_type = std::uint64_t;  ///< what operator() returns (a UniformRandomBitGenerator)
  /// A stream from `seed` (any 64-bit value; expanded with SplitMix64).
  explicit Random(std::uint64_t seed = 0) { reseed(seed); }
  /// Restarts the stream from `seed`, as a new Random(seed) would.
  void reseed(std::uint64_t seed);

  /// The smallest number operator() returns.
  static constexpr result_type min() { return 0; }
  /// The largest number operator() returns.
  static constexpr result_type max() { return ~result_type{0}; }
  /// The next raw 64-bit number.
  result_type operator()() {
    // xoshiro256++ (Blackman and Vigna); inline, as uniform and normal's second number: a sensor
    // draws a dozen numbers per sample, thousands of times per step
    const std::uint64_t result = rotl(s_[0] + s_[3], 23) + s_[0];
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  /// Uniform in [0, 1): 53 random bits.
  double uniform() { return static_cast<double>((*this)() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Standard normal (Marsaglia's polar method: numbers come in pairs, the second is kept).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    return normalPair();
  }
  /// Normal with mean and standard deviation.
  double normal(double mean, double stddev) { return mean + stddev * normal(); }

  /// The generator's whole state (for Environment::saveState), and back.
  void save(StateWriter& out) const;
  /// @copydoc save
  void load(StateReader& in);

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  double normalPair();  // draws a pair: returns the first, keeps the second
  std::uint64_t s_[4]{};
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace ssx
