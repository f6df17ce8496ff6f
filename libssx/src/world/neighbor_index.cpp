#include "world/neighbor_index.hpp"
#include "world/world.hpp"

namespace ssx::detail {

bool NeighborIndex::enable(double cell_size) {
  if (!(cell_size > 0)) throw Error("enableNeighborQueries: cell size must be positive");
  // positions do not change while plugins are configured: only a new grid needs building
  const bool is_new = !enabled_ || cell_size < index_.cellSize();
  if (is_new) index_ = SpatialIndex(cell_size);
  roots_of_ = ~std::size_t{0};
  enabled_ = true;
  return is_new;
}

void NeighborIndex::rebuild() const {
  // one point per artifact with a dynamic root: its first dynamic root's position
  const World& w = *world_;
  if (roots_of_ != w.artifacts.size()) {
    root_nodes_.clear();
    ids_.clear();
    for (const auto& a : w.artifacts) {
      if (w.artifact_data[a->index()].absent) continue;  // out of the world
      for (std::size_t r = 0; r < a->rootCount(); ++r) {
        const PhysicNode& root = a->root(r);
        if (root.isStatic()) continue;
        root_nodes_.push_back(static_cast<std::uint32_t>(root.nodeIndex()));
        ids_.push_back(a->index());
        break;
      }
    }
    roots_of_ = w.artifacts.size();
  }
  points_.resize(root_nodes_.size());
  for (std::size_t k = 0; k < root_nodes_.size(); ++k) points_[k] = w.nodePose(root_nodes_[k]).position;
  index_.rebuild(points_, ids_);
}

const SpatialIndex& NeighborIndex::fresh() const {
  if (stale_.load(std::memory_order_acquire)) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (stale_.load(std::memory_order_relaxed)) {
      rebuild();
      stale_.store(false, std::memory_order_release);
    }
  }
  return index_;
}

void NeighborIndex::requireEnabled() const {
  if (!enabled_) throw Error("neighbour queries are off: call enableNeighborQueries from configure");
}

void NeighborIndex::query(const Vec3& point, double radius, std::vector<std::size_t>& out) const {
  requireEnabled();
  fresh().query(point, radius, out);
}

void NeighborIndex::query(const Vec3& point, double radius, std::vector<SpatialIndex::Hit>& out) const {
  requireEnabled();
  fresh().query(point, radius, out);
}

void NeighborIndex::forEach(const Vec3& point, double radius, SpatialIndex::Visitor visit, void* context) const {
  requireEnabled();
  fresh().forEach(point, radius, visit, context);
}

}  // namespace ssx::detail
