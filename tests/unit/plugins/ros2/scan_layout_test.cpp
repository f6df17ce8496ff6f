#include "../../../../plugins/ros2/scan_layout.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using ssx::ros2::scanLayout;

namespace {
double deg(double d) { return d * std::numbers::pi / 180.0; }
// each ray's direction as the LaserScan lays it: angle_min + slot * increment
double laid(const ssx::ros2::ScanLayout& l, std::size_t ray) {
  return l.angle_min + static_cast<double>(l.slot_of[ray]) * l.angle_increment;
}
}  // namespace

TEST_CASE("a proximity ring as a LaserScan: evenly spaced rays are the scan's own, others on a common grid", "[ros2]") {
  // eight rays evenly spaced from straight ahead: 45 degrees apart, from -135 to 180
  std::vector<double> even;
  for (int k = 0; k < 8; ++k) even.push_back(deg(45.0 * k));
  const auto e = scanLayout(even);
  CHECK(e.angle_increment == Approx(deg(45)));
  CHECK(e.slots == 8);
  for (std::size_t k = 0; k < even.size(); ++k) CHECK(std::cos(laid(e, k) - even[k]) == Approx(1.0).margin(1e-12));
  // the e-puck's ring (in its order): on a grid of one degree, each ray exact, 303 slots
  const std::vector<double> epuck = {deg(-17), deg(-46), deg(-90), deg(-151), deg(151), deg(90), deg(46), deg(17)};
  const auto p = scanLayout(epuck);
  CHECK(p.angle_increment == Approx(deg(1)));
  CHECK(p.angle_min == Approx(deg(-151)));
  CHECK(p.slots == 303);
  for (std::size_t k = 0; k < epuck.size(); ++k) CHECK(laid(p, k) == Approx(epuck[k]).margin(1e-9));
  // rays on no common grid: half a degree, each within a quarter of a degree, all in slots of their own
  const std::vector<double> odd = {0.0, 0.3, 1.0 + 1e-4, std::sqrt(2.0)};
  const auto o = scanLayout(odd);
  CHECK(o.angle_increment == Approx(deg(0.5)));
  for (std::size_t k = 0; k < odd.size(); ++k) CHECK(std::abs(laid(o, k) - odd[k]) <= deg(0.25) + 1e-12);
  for (std::size_t k = 1; k < odd.size(); ++k) CHECK(o.slot_of[k] != o.slot_of[k - 1]);
  // one ray
  const auto one = scanLayout({deg(30)});
  CHECK(one.slots == 1);
  CHECK(one.slot_of == std::vector<std::size_t>{0});
  CHECK(one.angle_min == Approx(deg(30)));
}
