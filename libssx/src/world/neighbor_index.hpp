#pragma once
// The index behind Environment::neighbors: each artifact with a dynamic root, at its first
// dynamic root's position as of the last snapshot. The snapshot marks it stale; the first query
// after that rebuilds it (once, whichever thread asks first; the others wait), so that steps in
// which nobody asks (a range sensor at 50 Hz in a 500 Hz step) do not pay for it. The positions do
// not change between a snapshot and the next physics step, so the index is the same whoever
// builds it.

#include <ssx/spatial_index.hpp>

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

namespace ssx::detail {

struct World;

class NeighborIndex {
 public:
  bool enabled() const noexcept { return enabled_; }
  /// Turns queries on with cells of at most `cell_size` m (the smallest asked for wins). Returns
  /// whether the grid is new (and must be rebuilt before the next query).
  bool enable(double cell_size);
  /// The snapshot moved: the artifacts are indexed again at the next query. Not during a query.
  void markStale(const World& world) noexcept {
    world_ = &world;
    stale_.store(true, std::memory_order_release);
  }
  /// Artifacts left the world or came back: which ones are indexed is worked out again too.
  void markMembersChanged(const World& world) noexcept {
    roots_of_ = ~std::size_t{0};
    markStale(world);
  }
  /// See Environment::neighbors. Throws when queries are off. Any thread, any number at once.
  void query(const Vec3& point, double radius, std::vector<std::size_t>& out) const;
  void query(const Vec3& point, double radius, std::vector<SpatialIndex::Hit>& out) const;
  void forEach(const Vec3& point, double radius, SpatialIndex::Visitor visit, void* context) const;

 private:
  void requireEnabled() const;
  const SpatialIndex& fresh() const;  // rebuilt first when stale
  void rebuild() const;
  bool enabled_ = false;
  const World* world_ = nullptr;
  // the node indexed for each artifact that has a dynamic root (its first), and the artifact's
  // index: found once for a world's artifacts (they are fixed once it runs), then read from the
  // world's tables in order, not through each artifact's handles
  mutable std::vector<std::uint32_t> root_nodes_;
  mutable std::size_t roots_of_ = ~std::size_t{0};  // how many artifacts root_nodes_ was found for
  mutable std::atomic<bool> stale_{false};
  mutable std::mutex mutex_;  // the one rebuild after a snapshot
  mutable SpatialIndex index_;
  mutable std::vector<Vec3> points_;
  mutable std::vector<std::size_t> ids_;
};

}  // namespace ssx::detail
