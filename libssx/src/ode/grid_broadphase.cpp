#include "ode/grid_broadphase.hpp"

#include <algorithm>
#include <cmath>

namespace ssx::detail {

void GridBroadphase::build(std::span<const Box> boxes) {
  boxes_ = boxes;
  entries_.clear();
  bands_.clear();
  big_.clear();
  band_chunks_ = 0;
  if (boxes.empty()) return;

  // the cell: twice the median box's largest side (boxes larger than a cell are tested against all)
  scratch_.clear();
  for (const Box& b : boxes) scratch_.push_back((b.max - b.min).maxCoeff());
  auto middle = scratch_.begin() + static_cast<std::ptrdiff_t>(scratch_.size() / 2);
  std::nth_element(scratch_.begin(), middle, scratch_.end());
  cell_ = std::max(2.0 * *middle, 1e-3);

  constexpr double kMaxBand = 4e18;  // band numbers stay inside int64 (positions are checked finite)
  for (int i = 0; i < static_cast<int>(boxes.size()); ++i) {
    const Box& b = boxes[static_cast<std::size_t>(i)];
    if ((b.max - b.min).maxCoeff() > cell_ || !std::isfinite(b.min.y()) || !std::isfinite(b.min.z())) {
      big_.push_back(i);
      continue;
    }
    const double y = std::clamp(std::floor(b.min.y() / cell_), -kMaxBand, kMaxBand);
    const double z = std::clamp(std::floor(b.min.z() / cell_), -kMaxBand, kMaxBand);
    entries_.push_back({static_cast<std::int64_t>(y), static_cast<std::int64_t>(z), b.min.x(), i});
  }
  std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
    if (a.y != b.y) return a.y < b.y;
    if (a.z != b.z) return a.z < b.z;
    if (a.min_x != b.min_x) return a.min_x < b.min_x;
    return a.box < b.box;
  });
  for (std::uint32_t k = 0; k < entries_.size();) {
    std::uint32_t end = k + 1;
    while (end < entries_.size() && entries_[end].y == entries_[k].y && entries_[end].z == entries_[k].z) ++end;
    bands_.push_back({entries_[k].y, entries_[k].z, k, end});
    k = end;
  }
  band_chunks_ = (bands_.size() + kBandsPerChunk - 1) / kBandsPerChunk;
}

bool GridBroadphase::pairable(int a, int b) const {
  const int oa = boxes_[static_cast<std::size_t>(a)].owner;
  const int ob = boxes_[static_cast<std::size_t>(b)].owner;
  return oa != ob && (oa >= 0 || ob >= 0);
}

bool GridBroadphase::overlap(int a, int b) const {
  const Box& p = boxes_[static_cast<std::size_t>(a)];
  const Box& q = boxes_[static_cast<std::size_t>(b)];
  return p.min.x() <= q.max.x() && q.min.x() <= p.max.x() && p.min.y() <= q.max.y() && q.min.y() <= p.max.y() &&
         p.min.z() <= q.max.z() && q.min.z() <= p.max.z();
}

const GridBroadphase::Band* GridBroadphase::findBand(std::int64_t y, std::int64_t z) const {
  auto it = std::lower_bound(bands_.begin(), bands_.end(), std::pair{y, z},
                             [](const Band& b, const std::pair<std::int64_t, std::int64_t>& key) {
                               return b.y != key.first ? b.y < key.first : b.z < key.second;
                             });
  if (it == bands_.end() || it->y != y || it->z != z) return nullptr;
  return &*it;
}

void GridBroadphase::sweepSelf(const Band& band, std::vector<std::pair<int, int>>& out) const {
  for (std::uint32_t k = band.begin; k < band.end; ++k) {
    const int a = entries_[k].box;
    const double max_x = boxes_[static_cast<std::size_t>(a)].max.x();
    for (std::uint32_t m = k + 1; m < band.end && entries_[m].min_x <= max_x; ++m)
      if (pairable(a, entries_[m].box) && overlap(a, entries_[m].box)) out.emplace_back(a, entries_[m].box);
  }
}

void GridBroadphase::sweep(const Band& p, const Band& q, std::vector<std::pair<int, int>>& out) const {
  // every box is at most a cell long: q's boxes that can reach a start at most a cell before it
  std::uint32_t first = q.begin;
  for (std::uint32_t k = p.begin; k < p.end; ++k) {
    const int a = entries_[k].box;
    const double min_x = entries_[k].min_x, max_x = boxes_[static_cast<std::size_t>(a)].max.x();
    while (first < q.end && entries_[first].min_x < min_x - cell_) ++first;
    for (std::uint32_t m = first; m < q.end && entries_[m].min_x <= max_x; ++m)
      if (pairable(a, entries_[m].box) && overlap(a, entries_[m].box)) out.emplace_back(a, entries_[m].box);
  }
}

void GridBroadphase::pairs(std::size_t chunk, std::vector<std::pair<int, int>>& out) const {
  if (chunk == band_chunks_) {
    // the large boxes, against each other
    for (std::size_t i = 0; i < big_.size(); ++i)
      for (std::size_t j = i + 1; j < big_.size(); ++j)
        if (pairable(big_[i], big_[j]) && overlap(big_[i], big_[j])) out.emplace_back(big_[i], big_[j]);
    return;
  }
  const std::size_t end = std::min(bands_.size(), (chunk + 1) * kBandsPerChunk);
  for (std::size_t b = chunk * kBandsPerChunk; b < end; ++b) {
    const Band& band = bands_[b];
    sweepSelf(band, out);
    // the neighbours after it in (y, z) order: (y, z+1), (y+1, z-1), (y+1, z), (y+1, z+1)
    if (const Band* q = findBand(band.y, band.z + 1)) sweep(band, *q, out);
    for (std::int64_t dz = -1; dz <= 1; ++dz)
      if (const Band* q = findBand(band.y + 1, band.z + dz)) sweep(band, *q, out);
    // and every large box
    for (std::uint32_t k = band.begin; k < band.end; ++k)
      for (const int big : big_)
        if (pairable(entries_[k].box, big) && overlap(entries_[k].box, big)) out.emplace_back(entries_[k].box, big);
  }
}

}  // namespace ssx::detail
