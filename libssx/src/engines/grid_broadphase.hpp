#pragma once
// A broadphase for many similar bodies: the pairs of axis-aligned boxes that overlap, found in
// parallel chunks whose results do not depend on how many threads ran them.
//
// Boxes no larger than the cell size c (the caller's: twice the median body) are sorted into bands of c by c in
// y and z, and by their lower x within a band; two such boxes can only overlap when their bands
// are neighbours, so each band is swept along x against itself and four of its eight neighbours
// (each pair of bands once). Larger boxes are tested against every box. Linear in the boxes
// however they are laid out; a sweep along one axis (ODE's SAP) is quadratic in a grid.

#include <ssx/types.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace ssx::detail {

class GridBroadphase {
 public:
  struct Box {
    Vec3 min, max;
    int owner = -1;  // boxes of one owner >= 0 never pair; two boxes of owner -1 (static) neither
    bool off = false;  // in no pair and found by no query (a body taken out of the world)
  };

  /// Sorts the boxes into bands of `cell` (serial; keeps a view of `boxes` for pairs()). The cell
  /// should not depend on the state (it orders the pairs): say twice the median box's diameter.
  void build(std::span<const Box> boxes, double cell);
  /// Independent parts of the search, for parallel threads: together they find each overlapping
  /// pair exactly once.
  std::size_t chunkCount() const { return band_chunks_ + (big_.empty() ? 0 : 1); }
  /// Appends the overlapping pairs of one chunk (box indices), in an order fixed by the boxes.
  void pairs(std::size_t chunk, std::vector<std::pair<int, int>>& out) const;
  /// Calls visit(box index) for every box of the last build that overlaps [min, max] (read only:
  /// safe from several threads at once until the next build).
  template <class Visit>
  void overlapping(const Vec3& min, const Vec3& max, Visit&& visit) const;

 private:
  struct Entry {
    std::int64_t y, z;  // band
    double min_x;
    int box;
  };
  struct Band {
    std::int64_t y, z;
    std::uint32_t begin, end;  // in entries_
  };
  static constexpr std::size_t kBandsPerChunk = 32;

  bool isBig(const Box& b) const;
  std::int64_t band(double v) const;
  bool pairable(int a, int b) const;
  bool overlap(int a, int b) const;
  void sweepSelf(const Band& band, std::vector<std::pair<int, int>>& out) const;
  void sweep(const Band& p, const Band& q, std::vector<std::pair<int, int>>& out) const;
  // the index of the first band at or after (y, z) in (y, z) order
  std::size_t firstBandFrom(std::int64_t y, std::int64_t z) const;

  std::span<const Box> boxes_;
  double cell_ = 1.0;
  std::vector<Entry> entries_;      // sorted; kept, as the start of the next build's sort
  std::vector<std::uint8_t> small_;  // per box: 1 in the bands, 0 large (the last build's)
  std::vector<Band> bands_;
  std::vector<int> big_;
  std::size_t band_chunks_ = 0;
};

template <class Visit>
void GridBroadphase::overlapping(const Vec3& min, const Vec3& max, Visit&& visit) const {
  const auto hit = [&](const Box& b) {
    return b.min.x() <= max.x() && min.x() <= b.max.x() && b.min.y() <= max.y() && min.y() <= b.max.y() &&
           b.min.z() <= max.z() && min.z() <= b.max.z();
  };
  // a small box lies in the band of its lower corner and reaches at most a cell beyond it
  const std::int64_t y0 = band(min.y()) - 1, y1 = band(max.y()), z0 = band(min.z()) - 1, z1 = band(max.z());
  for (std::int64_t y = y0; y <= y1; ++y) {
    for (std::size_t b = firstBandFrom(y, z0); b < bands_.size() && bands_[b].y == y && bands_[b].z <= z1; ++b) {
      const Band& band = bands_[b];
      for (std::uint32_t k = band.begin; k < band.end && entries_[k].min_x <= max.x(); ++k)
        if (entries_[k].min_x >= min.x() - cell_ && hit(boxes_[static_cast<std::size_t>(entries_[k].box)]))
          visit(entries_[k].box);
    }
  }
  for (const int big : big_)
    if (hit(boxes_[static_cast<std::size_t>(big)])) visit(big);
}

}  // namespace ssx::detail
