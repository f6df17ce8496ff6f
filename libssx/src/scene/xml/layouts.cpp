#include "scene/xml/layouts.hpp"

#include <ssx/spatial_index.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ssx::detail {

std::vector<Vec3> gridLayout(std::int64_t count, double spacing, std::int64_t columns, std::int64_t rows) {
  std::vector<Vec3> out;
  out.reserve(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i)
    out.emplace_back(spacing * static_cast<double>(i % columns), spacing * static_cast<double>((i / columns) % rows),
                     spacing * static_cast<double>(i / (columns * rows)));
  return out;
}

std::vector<Vec3> randomLayout(std::int64_t count, const Vec3& lo, const Vec3& hi, double min_distance, Random& rng) {
  std::vector<Vec3> out;
  out.reserve(static_cast<std::size_t>(count));
  // the accepted points are found with the neighbour index, rebuilt now and then; the few
  // accepted since its last rebuild are checked one by one
  SpatialIndex index(min_distance > 0 ? min_distance : 1.0);
  std::size_t indexed = 0;
  std::vector<std::size_t> ids;
  std::vector<std::size_t> near;
  const std::int64_t max_tries = 1000 * count;
  for (std::int64_t tries = 0; static_cast<std::int64_t>(out.size()) < count && tries < max_tries; ++tries) {
    // draws in a fixed order (the order of function arguments is unspecified in C++)
    const double x = rng.uniform(lo.x(), hi.x());
    const double y = rng.uniform(lo.y(), hi.y());
    const double z = rng.uniform(lo.z(), hi.z());
    const Vec3 p(x, y, z);
    if (min_distance > 0) {
      auto tooClose = [&](std::size_t q) { return (p - out[q]).norm() < min_distance; };
      near.clear();
      index.query(p, min_distance, near);
      if (std::any_of(near.begin(), near.end(), tooClose)) continue;
      bool clear = true;
      for (std::size_t q = indexed; q < out.size() && clear; ++q) clear = !tooClose(q);
      if (!clear) continue;
    }
    out.push_back(p);
    if (out.size() - indexed >= std::max<std::size_t>(64, indexed / 8)) {
      ids.resize(out.size());
      for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = i;
      index.rebuild(out, ids);
      indexed = out.size();
    }
  }
  return out;
}

std::vector<Vec3> sphereLayout(std::int64_t count, double radius) {
  std::vector<Vec3> out;
  out.reserve(static_cast<std::size_t>(count));
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (std::int64_t i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(count);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double theta = golden * static_cast<double>(i);
    out.emplace_back(radius * r * std::cos(theta), radius * r * std::sin(theta), radius * z);
  }
  return out;
}

}  // namespace ssx::detail
