#pragma once
/// @file
/// Random streams that give the same numbers on every platform and thread count.

#include <ssx/export.hpp>

#include <cstdint>

namespace ssx {

class StateWriter;
class StateReader;

/// Mixes a seed with stream indices into an independent 64-bit seed (SplitMix64 finaliser).
/// Every stream in ssx is derived from (scene seed, artifact index, plugin index).
SSX_EXPORT std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0);

/// A small, fast generator (xoshiro256++) with its own distributions, written here so that the
/// numbers do not depend on the standard library's implementation. Not thread-safe: one stream
/// belongs to one plugin instance.
class SSX_EXPORT Random {
 public:
  using result_type = std::uint64_t;
  explicit Random(std::uint64_t seed = 0) { reseed(seed); }
  void reseed(std::uint64_t seed);

  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return ~result_type{0}; }
  /// The next raw 64-bit number.
  result_type operator()();
  /// Uniform in [0, 1).
  double uniform();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Standard normal (Marsaglia's polar method).
  double normal();
  /// Normal with mean and standard deviation.
  double normal(double mean, double stddev) { return mean + stddev * normal(); }

  /// The generator's whole state (for Environment::saveState), and back.
  void save(StateWriter& out) const;
  void load(StateReader& in);

 private:
  std::uint64_t s_[4]{};
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace ssx
