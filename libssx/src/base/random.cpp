#include <ssx/random.hpp>
#include <ssx/state.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iterator>

namespace ssx {

namespace {

std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

std::optional<std::uint64_t> parseSeed(std::string_view text) {
  if (text.empty() || text.front() < '0' || text.front() > '9') return std::nullopt;
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return v;
}

std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  // chain the three values through SplitMix64 so that nearby indices give unrelated seeds
  std::uint64_t state = seed;
  std::uint64_t h = splitmix64(state);
  state = h ^ (a * 0xd1342543de82ef95ULL);
  h = splitmix64(state);
  state = h ^ (b * 0xaf251af3b0f025b5ULL);
  return splitmix64(state);
}

void Random::reseed(std::uint64_t seed) {
  std::uint64_t state = seed;
  for (auto& s : s_) s = splitmix64(state);
  has_spare_ = false;
}

double Random::normalPair() {
  double u, v, s;
  do {
    u = 2.0 * uniform() - 1.0;
    v = 2.0 * uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double f = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * f;
  has_spare_ = true;
  return u * f;
}

void Random::save(StateWriter& out) const {
  for (std::uint64_t word : s_) out.write(word);
  out.write(spare_);
  out.write(has_spare_);
}

void Random::load(StateReader& in) {
  // read whole and checked before anything changes: xoshiro never reaches the all-zero state (it
  // would stay there, and the polar method would draw for ever), and a kept number is finite
  std::uint64_t words[4];
  for (std::uint64_t& word : words) in.read(word);
  double spare = 0;
  bool has_spare = false;
  in.read(spare);
  in.read(has_spare);
  if ((words[0] | words[1] | words[2] | words[3]) == 0)
    throw StateError(in.what() + ": a random stream's state is all zero, which no stream reaches (corrupted)");
  if (has_spare && !std::isfinite(spare))
    throw StateError(in.what() + ": a random stream keeps a number that is not finite (corrupted)");
  std::copy(std::begin(words), std::end(words), std::begin(s_));
  spare_ = spare;
  has_spare_ = has_spare;
}

}  // namespace ssx
