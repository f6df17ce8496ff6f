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
  };

  /// Sorts the boxes into bands of `cell` (serial; keeps a view of `boxes` for pairs()). The cell
  /// should not depend on the state (it orders the pairs): say twice the median box's diameter.
  void build(std::span<const Box> boxes, double cell);
  /// Independent parts of the search, for parallel threads: together they find each overlapping
  /// pair exactly once.
  std::size_t chunkCount() const { return band_chunks_ + (big_.empty() ? 0 : 1); }
  /// Appends the overlapping pairs of one chunk (box indices), in an order fixed by the boxes.
  void pairs(std::size_t chunk, std::vector<std::pair<int, int>>& out) const;

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

}  // namespace ssx::detail
