#include <ssx/random.hpp>
#include <ssx/state.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

TEST_CASE("random streams repeat for the same seed and differ between seeds", "[random]") {
  ssx::Random a(123), b(123), c(124);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const auto x = a();
    CHECK(x == b());
    differs = differs || x != c();
  }
  CHECK(differs);
}

TEST_CASE("derived seeds differ per artifact and plugin", "[random]") {
  const auto s00 = ssx::deriveSeed(7, 0, 0);
  CHECK(s00 != ssx::deriveSeed(7, 1, 0));
  CHECK(s00 != ssx::deriveSeed(7, 0, 1));
  CHECK(ssx::deriveSeed(7, 1, 0) != ssx::deriveSeed(7, 0, 1));
  CHECK(s00 != ssx::deriveSeed(8, 0, 0));
  CHECK(s00 == ssx::deriveSeed(7, 0, 0));
}

TEST_CASE("uniform and normal draws have the right moments", "[random]") {
  ssx::Random r(99);
  const int n = 200000;
  double su = 0, sn = 0, sn2 = 0;
  double lo = 1, hi = 0;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    lo = std::min(lo, u);
    hi = std::max(hi, u);
    su += u;
    const double z = r.normal(2.0, 3.0);
    sn += z;
    sn2 += z * z;
  }
  CHECK(lo >= 0.0);
  CHECK(hi < 1.0);
  CHECK(su / n == Approx(0.5).margin(0.005));
  const double mean = sn / n;
  const double var = sn2 / n - mean * mean;
  CHECK(mean == Approx(2.0).margin(0.03));
  CHECK(std::sqrt(var) == Approx(3.0).epsilon(0.01));
}

TEST_CASE("normal draws follow the normal distribution, tails included", "[random]") {
  // the ziggurat's layers, wedges and tail each cover part of the curve: a mistake in one shows
  // as a distance between the sample's distribution and the normal one, or as a wrong tail mass
  ssx::Random r(7);
  const int n = 1000000;
  std::vector<double> z(n);
  double m4 = 0;
  int beyond_r = 0, beyond_4 = 0;
  for (double& v : z) {
    v = r.normal();
    m4 += v * v * v * v;
    beyond_r += std::abs(v) > 3.6541528853610088;
    beyond_4 += std::abs(v) > 4.0;
  }
  std::sort(z.begin(), z.end());
  double ks = 0;  // Kolmogorov-Smirnov distance
  for (int i = 0; i < n; ++i) {
    const double cdf = 0.5 * std::erfc(-z[static_cast<std::size_t>(i)] / std::sqrt(2.0));
    ks = std::max({ks, std::abs(cdf - static_cast<double>(i) / n), std::abs(cdf - static_cast<double>(i + 1) / n)});
  }
  // 1.63 / sqrt(n) is the 1 % critical value
  CHECK(ks < 1.63 / std::sqrt(static_cast<double>(n)));
  CHECK(m4 / n == Approx(3.0).margin(0.03));
  // P(|z| > 3.654) = 2.58e-4 (the tail the bottom layer draws), P(|z| > 4) = 6.33e-5: within 5 sigma
  const double p_r = std::erfc(3.6541528853610088 / std::sqrt(2.0)), p_4 = std::erfc(4.0 / std::sqrt(2.0));
  CHECK(std::abs(beyond_r - n * p_r) < 5 * std::sqrt(n * p_r));
  CHECK(std::abs(beyond_4 - n * p_4) < 5 * std::sqrt(n * p_4));
  CHECK(z.front() < -4.0);
  CHECK(z.back() > 4.0);
}

TEST_CASE("a saved stream reads back to the same numbers, and an all-zero or non-finite one is refused unchanged",
          "[random][state]") {
  using ssx::Random, ssx::StateReader, ssx::StateWriter;
  Random a(42);
  a.normal();  // a second number kept
  std::vector<std::byte> saved;
  StateWriter out(saved);
  a.save(out);
  Random b(7);
  StateReader in(saved);
  b.load(in);
  CHECK(b.normal() == a.normal());
  CHECK(b() == a());

  // xoshiro's all-zero state is a fixed point: the polar method would draw for ever (a fuzzer's
  // corrupted state hung a pose sensor); refused, the stream left as it was
  std::vector<std::byte> zero(4 * sizeof(std::uint64_t) + sizeof(double) + 1, std::byte{0});
  Random c(3), same(3);
  StateReader zero_in(zero);
  CHECK_THROWS_WITH(c.load(zero_in), Catch::Contains("all zero"));
  CHECK(c() == same());
  std::vector<std::byte> nan = saved;
  const double bad = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(nan.data() + 4 * sizeof(std::uint64_t), &bad, sizeof bad);
  nan[4 * sizeof(std::uint64_t) + sizeof(double)] = std::byte{1};
  StateReader nan_in(nan);
  CHECK_THROWS_WITH(c.load(nan_in), Catch::Contains("not finite"));
}
