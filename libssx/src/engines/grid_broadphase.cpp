#include "engines/grid_broadphase.hpp"

#include <algorithm>
#include <cmath>

namespace ssx::detail {

bool GridBroadphase::isBig(const Box& b) const {
  return (b.max - b.min).maxCoeff() > cell_ || !std::isfinite(b.min.y()) || !std::isfinite(b.min.z());
}

std::int64_t GridBroadphase::band(double v) const {
  constexpr double kMaxBand = 4e18;  // band numbers stay inside int64
  return static_cast<std::int64_t>(std::clamp(std::floor(v / cell_), -kMaxBand, kMaxBand));
}

void GridBroadphase::build(std::span<const Box> boxes, double cell) {
  boxes_ = boxes;
  bands_.clear();
  big_.clear();
  band_chunks_ = 0;
  if (boxes.empty()) return;

  // boxes larger than a cell are tested against all
  if (boxes.size() != small_.size() || cell != cell_) {
    cell_ = cell;
    small_.assign(boxes.size(), 3);  // (none of them: the entries are made again below)
    big_.reserve(boxes.size());
  }
  // the entries of the last build, moved to where their boxes are now: bodies move little from one
  // step to the next, so they are nearly in order and an insertion sort costs about one pass
  bool same = true;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    // 1: in the bands, 0: large, 2: off (in neither)
    const std::uint8_t is_small = boxes[i].off ? 2 : isBig(boxes[i]) ? 0 : 1;
    if (is_small == 0) big_.push_back(static_cast<int>(i));
    same = same && small_[i] == is_small;
    small_[i] = is_small;
  }
  if (!same) {
    entries_.clear();
    for (std::size_t i = 0; i < boxes.size(); ++i)
      if (small_[i] == 1) entries_.push_back({0, 0, 0, static_cast<int>(i)});
  }
  for (Entry& e : entries_) {
    const Box& b = boxes[static_cast<std::size_t>(e.box)];
    e.y = band(b.min.y());
    e.z = band(b.min.z());
    e.min_x = b.min.x();
  }
  const auto before = [](const Entry& a, const Entry& b) {
    if (a.y != b.y) return a.y < b.y;
    if (a.z != b.z) return a.z < b.z;
    if (a.min_x != b.min_x) return a.min_x < b.min_x;
    return a.box < b.box;
  };
  // insertion sort with a budget; past it, a full sort (the same order either way: it is total)
  std::size_t moves = 0;
  const std::size_t budget = 8 * entries_.size() + 64;
  for (std::size_t k = 1; k < entries_.size() && moves <= budget; ++k) {
    const Entry e = entries_[k];
    std::size_t m = k;
    for (; m > 0 && before(e, entries_[m - 1]) && moves <= budget; --m, ++moves) entries_[m] = entries_[m - 1];
    entries_[m] = e;
  }
  if (moves > budget) std::sort(entries_.begin(), entries_.end(), before);
  // at most one band per entry: room for them all once, so that no later step allocates when
  // bodies spread over more bands than before
  bands_.reserve(entries_.size());
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

std::size_t GridBroadphase::firstBandFrom(std::int64_t y, std::int64_t z) const {
  return static_cast<std::size_t>(
      std::lower_bound(bands_.begin(), bands_.end(), std::pair{y, z},
                       [](const Band& b, const std::pair<std::int64_t, std::int64_t>& key) {
                         return b.y != key.first ? b.y < key.first : b.z < key.second;
                       }) -
      bands_.begin());
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
  const std::size_t begin = chunk * kBandsPerChunk;
  const std::size_t end = std::min(bands_.size(), (chunk + 1) * kBandsPerChunk);
  // the bands are in (y, z) order, one per key: the neighbours of band b that come after it,
  // (y, z+1) then (y+1, z-1), (y+1, z), (y+1, z+1), are band b+1 if it is (y, z+1), and a run
  // that starts at the first band from (y+1, z-1), which only moves forward as b does
  std::size_t next_row = begin < end ? firstBandFrom(bands_[begin].y + 1, bands_[begin].z - 1) : end;
  for (std::size_t b = begin; b < end; ++b) {
    const Band& band = bands_[b];
    sweepSelf(band, out);
    if (b + 1 < bands_.size() && bands_[b + 1].y == band.y && bands_[b + 1].z == band.z + 1)
      sweep(band, bands_[b + 1], out);
    while (next_row < bands_.size() && (bands_[next_row].y != band.y + 1 ? bands_[next_row].y < band.y + 1
                                                                         : bands_[next_row].z < band.z - 1))
      ++next_row;
    for (std::size_t q = next_row; q < bands_.size() && bands_[q].y == band.y + 1 && bands_[q].z <= band.z + 1; ++q)
      sweep(band, bands_[q], out);
    // and every large box
    for (std::uint32_t k = band.begin; k < band.end; ++k)
      for (const int big : big_)
        if (pairable(entries_[k].box, big) && overlap(entries_[k].box, big)) out.emplace_back(entries_[k].box, big);
  }
}

}  // namespace ssx::detail
