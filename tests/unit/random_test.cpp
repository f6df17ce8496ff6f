#include <ssx/random.hpp>

#include <catch2/catch.hpp>

#include <cmath>
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
