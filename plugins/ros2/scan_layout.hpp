#pragma once
// A proximity ring as a sensor_msgs/LaserScan, whose rays are evenly spaced from angle_min: the
// ring's rays laid on such a grid, each in its own slot, the slots between them NaN (REP 117: no
// measurement). A ring whose rays are all on a common grid (evenly spaced ones; the e-puck's 17,
// 46, 90 and 151 degrees on a grid of 1) keeps each ray's direction exactly; any other is laid on a
// grid of 0.5 degrees, each ray within 0.25 degrees of its own direction.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

namespace ssx::ros2 {

struct ScanLayout {
  double angle_min = 0;        ///< rad, the first slot's direction
  double angle_increment = 0;  ///< rad between two slots (0: one ray)
  std::size_t slots = 0;       ///< ranges in a message
  std::vector<std::size_t> slot_of;  ///< per ray, in the ring's order
};

/// The grid for rays at `angles` (rad, any order, each taken in (-pi, pi]); at most `max_slots`
/// slots (a finer common grid than that is dropped for the 0.5-degree one).
inline ScanLayout scanLayout(const std::vector<double>& angles, std::size_t max_slots = 4096) {
  ScanLayout l;
  if (angles.empty()) return l;
  std::vector<double> a;
  for (double x : angles) a.push_back(std::remainder(x, 2 * std::numbers::pi));
  std::vector<double> sorted = a;
  std::sort(sorted.begin(), sorted.end());
  l.angle_min = sorted.front();
  const double span = sorted.back() - sorted.front();
  double gap = span;
  for (std::size_t k = 1; k < sorted.size(); ++k)
    if (sorted[k] - sorted[k - 1] > 1e-12) gap = std::min(gap, sorted[k] - sorted[k - 1]);
  auto onGrid = [&](double step) {
    for (double x : sorted) {
      const double q = (x - l.angle_min) / step;
      if (std::abs(q - std::round(q)) * step > 1e-9) return false;
    }
    return true;
  };
  double step = 0;
  if (sorted.size() > 1 && gap > 0) {
    // the coarsest common grid: the smallest gap divided by 1, 2, 3, ...
    for (int d = 1; d <= 3600 && step == 0; ++d) {
      const double s = gap / d;
      if (span / s + 1 > static_cast<double>(max_slots)) break;
      if (onGrid(s)) step = s;
    }
    if (step == 0) step = std::min(gap / 2, std::numbers::pi / 360);  // (0.5 degrees, or finer for close rays)
  }
  l.angle_increment = step;
  l.slots = step > 0 ? static_cast<std::size_t>(std::llround(span / step)) + 1 : 1;
  for (double x : a) l.slot_of.push_back(step > 0 ? static_cast<std::size_t>(std::llround((x - l.angle_min) / step)) : 0);
  return l;
}

}  // namespace ssx::ros2
