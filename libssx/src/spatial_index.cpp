#include <ssx/error.hpp>
#include <ssx/spatial_index.hpp>

#include <algorithm>
#include <cmath>

namespace ssx {

namespace {
// 21 bits per axis, offset so that negative cells pack too: +-1,048,575 cells (+-2,000 km at 2 m)
constexpr std::int64_t kAxisOffset = std::int64_t{1} << 20;
constexpr std::int64_t kAxisMax = (std::int64_t{1} << 21) - 1;
}  // namespace

SpatialIndex::SpatialIndex(double cell_size) : cell_size_(cell_size) {
  if (!(cell_size > 0) || !std::isfinite(cell_size)) throw Error("spatial index: cell size must be positive");
}

std::int64_t SpatialIndex::cell(double v) const {
  return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor(v / cell_size_)) + kAxisOffset, 0, kAxisMax);
}

std::uint64_t SpatialIndex::key(std::int64_t x, std::int64_t y, std::int64_t z) const {
  return (static_cast<std::uint64_t>(x) << 42) | (static_cast<std::uint64_t>(y) << 21) | static_cast<std::uint64_t>(z);
}

void SpatialIndex::rebuild(const std::vector<Vec3>& points, const std::vector<std::size_t>& ids) {
  entries_.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    entries_[i] = {key(cell(p.x()), cell(p.y()), cell(p.z())), ids[i], p};
  }
  std::sort(entries_.begin(), entries_.end(),
            [](const Entry& a, const Entry& b) { return a.key != b.key ? a.key < b.key : a.id < b.id; });
}

void SpatialIndex::query(const Vec3& center, double radius, std::vector<std::size_t>& out) const {
  const std::size_t first = out.size();
  const double r2 = radius * radius;
  const std::int64_t x0 = cell(center.x() - radius), x1 = cell(center.x() + radius);
  const std::int64_t y0 = cell(center.y() - radius), y1 = cell(center.y() + radius);
  const std::int64_t z0 = cell(center.z() - radius), z1 = cell(center.z() + radius);
  for (std::int64_t x = x0; x <= x1; ++x) {
    for (std::int64_t y = y0; y <= y1; ++y) {
      // the cells of one (x, y) column are contiguous in key order: one search per column
      const std::uint64_t lo = key(x, y, z0), hi = key(x, y, z1);
      auto it = std::lower_bound(entries_.begin(), entries_.end(), lo,
                                 [](const Entry& e, std::uint64_t k) { return e.key < k; });
      for (; it != entries_.end() && it->key <= hi; ++it)
        if ((it->point - center).squaredNorm() <= r2) out.push_back(it->id);
    }
  }
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
}

}  // namespace ssx
