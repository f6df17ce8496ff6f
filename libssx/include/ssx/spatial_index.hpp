#pragma once
/// @file
/// A uniform-grid index of points for neighbour queries: its contents replaced whole by each
/// rebuild (entries sorted by cell key), queried for everything within a radius. Building is
/// O(n log n) in the points, or O(n + m log m) when they are as many as last time and m of them
/// changed cells (a swarm from one step to the next: the others keep the last order). A query is
/// O(columns probed + points scanned). When the points' (x, y) columns fill a good part of their
/// bounding rectangle (a swarm), a dense table of the rectangle's columns finds a query's columns
/// of one x as one contiguous run of entries; else a hash table finds each column.

#include <ssx/export.hpp>
#include <ssx/types.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace ssx {

/// A uniform grid over points with ids, for "who is within r of here" queries: the neighbour
/// queries of Environment and the range sensors use one. Rebuilt whole each step; queries are
/// read-only and safe from many threads at once.
class SSX_EXPORT SpatialIndex {
 public:
  /// `cell_size` in m; queries are cheapest when it is about the typical query radius.
  explicit SpatialIndex(double cell_size = 2.0);

  /// The cell edge length, m.
  double cellSize() const noexcept { return cell_size_; }
  /// Replaces the contents: point i gets the id ids[i] (ids.size() == points.size()).
  void rebuild(const std::vector<Vec3>& points, const std::vector<std::size_t>& ids);
  /// Appends to `out` the ids of the points within `radius` of `center` (distance <= radius),
  /// in ascending id order. Safe to call from many threads at once.
  void query(const Vec3& center, double radius, std::vector<std::size_t>& out) const;
  /// A point found by a query: its id and indexed position.
  struct Hit {
    std::size_t id;  ///< the id given to rebuild
    Vec3 point;      ///< the position indexed
  };
  /// Same, with the points (in ascending id order).
  void query(const Vec3& center, double radius, std::vector<Hit>& out) const;
  /// Calls visit(context, id, point) for each point within `radius` of `center`, in the index's
  /// order (no particular one): for a caller that orders what it keeps itself, without a list.
  using Visitor = void (*)(void* context, std::size_t id, const Vec3& point);
  /// @copydoc Visitor
  void forEach(const Vec3& center, double radius, Visitor visit, void* context) const;
  /// How many points the last rebuild indexed.
  std::size_t size() const noexcept { return entries_.size(); }
  /// Whether the last rebuild chose the dense column table (else the hash table).
  bool dense() const noexcept { return !dense_start_.empty(); }

 private:
  struct Entry {
    std::uint64_t key;
    std::size_t id;
    Vec3 point;
    std::uint32_t input;  // its index in rebuild's arguments (orders equal (key, id) pairs)
  };
  void sortEntries(const std::vector<Vec3>& points, const std::vector<std::size_t>& ids);
  std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z) const;
  std::int64_t cell(double v) const;
  template <class Visit>
  void visit(const Vec3& center, double radius, Visit&& found) const;

  // the entries of one (x, y) column of cells, which are contiguous in key order
  struct Column {
    std::uint64_t key = ~std::uint64_t{0};  // key >> 21; all ones: empty slot
    std::uint32_t begin = 0, end = 0;
  };
  const Column* findColumn(std::uint64_t column_key) const;

  double cell_size_;
  std::vector<Entry> entries_;   // sorted by (key, id, input)
  std::vector<Entry> moved_;     // rebuild's scratch: the entries whose cell or id changed
  std::vector<Column> columns_;  // open-addressing hash table of the non-empty columns (sparse)
  // dense: the columns of cells [x_min, x_min + nx) x [y_min, y_min + ny), x-major as the keys are;
  // column c's entries are [dense_start_[c], dense_start_[c + 1])
  std::vector<std::uint32_t> dense_start_;
  std::int64_t x_min_ = 0, y_min_ = 0, nx_ = 0, ny_ = 0;
};

}  // namespace ssx
