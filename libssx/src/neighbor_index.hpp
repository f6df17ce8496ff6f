#pragma once
// The index behind Environment::neighbors: each artifact with a dynamic root, at its first
// dynamic root's position, rebuilt once per step in the snapshot phase and read by any thread in
// the parallel phases.

#include <ssx/artifact.hpp>
#include <ssx/spatial_index.hpp>

#include <memory>
#include <vector>

namespace ssx::detail {

class NeighborIndex {
 public:
  using Artifacts = std::vector<std::unique_ptr<Artifact>>;

  bool enabled() const noexcept { return enabled_; }
  /// Turns queries on with cells of at most `cell_size` m (the smallest asked for wins). Returns
  /// whether the grid is new (and must be rebuilt before the next query).
  bool enable(double cell_size);
  /// Indexes the artifacts at their snapshot positions.
  void rebuild(const Artifacts& artifacts);
  /// See Environment::neighbors. Throws when queries are off.
  void query(const Vec3& point, double radius, std::vector<std::size_t>& out) const;
  void query(const Vec3& point, double radius, std::vector<SpatialIndex::Hit>& out) const;

 private:
  void requireEnabled() const;
  bool enabled_ = false;
  SpatialIndex index_;
  std::vector<Vec3> points_;
  std::vector<std::size_t> ids_;
};

}  // namespace ssx::detail
