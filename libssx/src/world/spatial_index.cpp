#include <ssx/error.hpp>
#include <ssx/spatial_index.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ssx {

namespace {
// 21 bits per axis, offset so that negative cells pack too: +-1,048,575 cells (+-2,000 km at 2 m)
constexpr std::int64_t kAxisOffset = std::int64_t{1} << 20;
constexpr std::int64_t kAxisMax = (std::int64_t{1} << 21) - 1;
constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no column has this key (it has 42 bits)

std::size_t hashColumn(std::uint64_t column) {
  // a multiplicative hash: neighbouring columns land in distant slots
  return static_cast<std::size_t>((column * 0x9E3779B97F4A7C15ull) >> 20);
}
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

void SpatialIndex::sortEntries(const std::vector<Vec3>& points, const std::vector<std::size_t>& ids) {
  auto before = [](const Entry& a, const Entry& b) {
    if (a.key != b.key) return a.key < b.key;
    return a.id != b.id ? a.id < b.id : a.input < b.input;
  };
  auto entry = [&](std::size_t i) {
    const Vec3& p = points[i];
    return Entry{key(cell(p.x()), cell(p.y()), cell(p.z())), ids[i], p, static_cast<std::uint32_t>(i)};
  };
  const std::size_t n = points.size();
  if (entries_.size() == n && n > 0) {
    // as many points as last time: the entries whose cell and id did not change keep the last
    // order among themselves; the others (a swarm's few that crossed a cell wall since) are sorted
    // apart and merged in. O(n + m log m) for m changed; the one order `before` defines either way
    moved_.clear();
    std::size_t kept = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const Entry e = entry(entries_[k].input);
      if (e.key == entries_[k].key && e.id == entries_[k].id)
        entries_[kept++] = e;
      else
        moved_.push_back(e);
    }
    if (moved_.empty()) return;
    std::sort(moved_.begin(), moved_.end(), before);
    // merge from the back, in place: the kept ones fill [0, kept), the moved ones go after
    std::size_t a = kept, b = moved_.size(), out = n;
    while (b > 0) {
      if (a > 0 && before(moved_[b - 1], entries_[a - 1]))
        entries_[--out] = entries_[--a];
      else
        entries_[--out] = moved_[--b];
    }
    return;
  }
  entries_.resize(n);
  for (std::size_t i = 0; i < n; ++i) entries_[i] = entry(i);
  std::sort(entries_.begin(), entries_.end(), before);
}

void SpatialIndex::rebuild(const std::vector<Vec3>& points, const std::vector<std::size_t>& ids) {
  if (ids.size() != points.size()) throw Error("spatial index: as many ids as points are needed");
  if (points.size() >= std::numeric_limits<std::uint32_t>::max()) throw Error("spatial index: too many points");
  sortEntries(points, ids);
  columns_.clear();
  dense_start_.clear();
  if (entries_.empty()) return;
  // dense when the bounding rectangle of the columns has at most 4 columns per point (or 4,096)
  std::int64_t x_max = 0, y_max = 0;
  x_min_ = y_min_ = kAxisMax;
  for (const Entry& e : entries_) {
    const auto x = static_cast<std::int64_t>(e.key >> 42), y = static_cast<std::int64_t>((e.key >> 21) & kAxisMax);
    x_min_ = std::min(x_min_, x);
    x_max = std::max(x_max, x);
    y_min_ = std::min(y_min_, y);
    y_max = std::max(y_max, y);
  }
  nx_ = x_max - x_min_ + 1;
  ny_ = y_max - y_min_ + 1;
  const auto limit = static_cast<double>(std::max<std::size_t>(4 * entries_.size(), 4096));
  if (static_cast<double>(nx_) * static_cast<double>(ny_) <= limit) {
    // counting, then prefix sums: the entries are sorted by column already
    dense_start_.assign(static_cast<std::size_t>(nx_ * ny_) + 1, 0);
    for (const Entry& e : entries_) {
      const auto x = static_cast<std::int64_t>(e.key >> 42), y = static_cast<std::int64_t>((e.key >> 21) & kAxisMax);
      ++dense_start_[static_cast<std::size_t>((x - x_min_) * ny_ + (y - y_min_)) + 1];
    }
    for (std::size_t c = 1; c < dense_start_.size(); ++c) dense_start_[c] += dense_start_[c - 1];
    return;
  }
  // a hash table of the columns, at most half full
  std::size_t slots = 16;
  while (slots < 2 * entries_.size()) slots *= 2;
  columns_.assign(slots, Column{});
  for (std::size_t i = 0; i < entries_.size();) {
    const std::uint64_t column = entries_[i].key >> 21;
    std::size_t j = i + 1;
    while (j < entries_.size() && (entries_[j].key >> 21) == column) ++j;
    std::size_t slot = hashColumn(column) & (slots - 1);
    while (columns_[slot].key != kEmpty) slot = (slot + 1) & (slots - 1);
    columns_[slot] = {column, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j)};
    i = j;
  }
}

const SpatialIndex::Column* SpatialIndex::findColumn(std::uint64_t column_key) const {
  if (columns_.empty()) return nullptr;
  const std::size_t mask = columns_.size() - 1;
  for (std::size_t slot = hashColumn(column_key) & mask;; slot = (slot + 1) & mask) {
    if (columns_[slot].key == column_key) return &columns_[slot];
    if (columns_[slot].key == kEmpty) return nullptr;
  }
}

template <class Visit>
void SpatialIndex::visit(const Vec3& center, double radius, Visit&& found) const {
  const double r2 = radius * radius;
  const std::int64_t x0 = cell(center.x() - radius), x1 = cell(center.x() + radius);
  const std::int64_t y0 = cell(center.y() - radius), y1 = cell(center.y() + radius);
  const std::int64_t z0 = cell(center.z() - radius), z1 = cell(center.z() + radius);
  if (!dense_start_.empty()) {
    // the columns y0..y1 of one x are adjacent in the table and their entries one run; in it,
    // only the cells of z0..z1 are looked at
    const std::int64_t ya = std::max(y0, y_min_) - y_min_, yb = std::min(y1, y_min_ + ny_ - 1) - y_min_;
    if (ya > yb) return;
    for (std::int64_t x = std::max(x0, x_min_); x <= std::min(x1, x_min_ + nx_ - 1); ++x) {
      const auto row = static_cast<std::size_t>((x - x_min_) * ny_);
      const Entry* end = entries_.data() + dense_start_[row + static_cast<std::size_t>(yb) + 1];
      for (const Entry* e = entries_.data() + dense_start_[row + static_cast<std::size_t>(ya)]; e != end; ++e) {
        const auto z = static_cast<std::int64_t>(e->key & kAxisMax);
        if (z >= z0 && z <= z1 && (e->point - center).squaredNorm() <= r2) found(*e);
      }
    }
    return;
  }
  for (std::int64_t x = x0; x <= x1; ++x) {
    for (std::int64_t y = y0; y <= y1; ++y) {
      // one hash lookup per column, then the column's entries in the z range
      const Column* c = findColumn(key(x, y, 0) >> 21);
      if (c == nullptr) continue;
      const std::uint64_t lo = key(x, y, z0), hi = key(x, y, z1);
      const Entry* end = entries_.data() + c->end;
      for (const Entry* e = entries_.data() + c->begin; e != end && e->key <= hi; ++e)
        if (e->key >= lo && (e->point - center).squaredNorm() <= r2) found(*e);
    }
  }
}

void SpatialIndex::forEach(const Vec3& center, double radius, Visitor visit_one, void* context) const {
  visit(center, radius, [&](const Entry& e) { visit_one(context, e.id, e.point); });
}

void SpatialIndex::query(const Vec3& center, double radius, std::vector<std::size_t>& out) const {
  const std::size_t first = out.size();
  visit(center, radius, [&](const Entry& e) { out.push_back(e.id); });
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
}

void SpatialIndex::query(const Vec3& center, double radius, std::vector<Hit>& out) const {
  const std::size_t first = out.size();
  visit(center, radius, [&](const Entry& e) { out.push_back({e.id, e.point}); });
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
            [](const Hit& a, const Hit& b) { return a.id < b.id; });
}

}  // namespace ssx
