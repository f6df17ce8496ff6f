// The Bullet engine's collision: geoms posed and boxed, the grid broadphase, fresh manifolds from
// Bullet's algorithms in parallel chunks joined in a fixed order, and bodies in contact made into
// islands (see bullet_engine.hpp for the whole substep).
#include "engines/bullet/bullet_parts.hpp"

#include <algorithm>

namespace ssx::detail {

using namespace bullet;

namespace {

// the velocity of an object's material point at `world` (a static object: zero)
btVector3 velocityAt(const btCollisionObject* object, const btVector3& world) {
  const btRigidBody* rb = btRigidBody::upcast(object);
  if (rb == nullptr) return btVector3(0, 0, 0);
  return rb->getVelocityInLocalPoint(world - rb->getCenterOfMassPosition());
}

}  // namespace

void BulletEngine::indexGeoms() {
  proxies_stale_ = false;
  proxies_.clear();
  boxes_.clear();
  first_proxy_.assign(bodies_.size(), 0);
  std::vector<double> diameters;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    first_proxy_[i] = static_cast<std::uint32_t>(proxies_.size());
    const Body& b = *bodies_[i];
    for (std::size_t k = 0; k < b.geoms.size(); ++k) {
      proxies_.push_back({b.rb.get(), b.geoms[k].shape.get(), static_cast<int>(i), static_cast<int>(k), -1});
      boxes_.push_back({Vec3::Zero(), Vec3::Zero(), static_cast<int>(i)});
      diameters.push_back(b.geoms[k].diameter);
    }
  }
  dynamic_proxies_ = proxies_.size();
  if (!diameters.empty()) {
    auto middle = diameters.begin() + static_cast<std::ptrdiff_t>(diameters.size() / 2);
    std::nth_element(diameters.begin(), middle, diameters.end());
    cell_ = std::max(2.0 * *middle, 1e-3);
  }
  const double margin = gContactBreakingThreshold / 2;
  for (std::size_t k = 0; k < statics_.size(); ++k) {
    const StaticObject& s = *statics_[k];
    if (s.plane) continue;
    btVector3 lo, hi;
    s.shape->getAabb(s.object->getWorldTransform(), lo, hi);
    proxies_.push_back({s.object.get(), s.shape.get(), -1, 0, static_cast<int>(k)});
    boxes_.push_back({fromBt(lo) - Vec3::Constant(margin), fromBt(hi) + Vec3::Constant(margin), -1});
  }
  poses_.resize(proxies_.size());
  for (std::size_t k = dynamic_proxies_; k < proxies_.size(); ++k)
    poses_[k].transform = proxies_[k].object->getWorldTransform();
  // room for what a substep usually needs, so that steps do not allocate: every body in contact
  // with a few others
  groups_.resize(bodies_.size());
  groups_.reserve(bodies_.size());
  members_.reserve(bodies_.size());
  island_bodies_.reserve(bodies_.size());
  islands_.reserve(bodies_.size());
  free_bodies_.reserve(bodies_.size());
  manifolds_.reserve(4 * bodies_.size() + 64);
  island_manifolds_.reserve(4 * bodies_.size() + 64);
  manifold_order_.reserve(4 * bodies_.size() + 64);
}

void BulletEngine::placeGeoms(std::size_t begin, std::size_t end) {
  const double margin = gContactBreakingThreshold / 2;
  for (std::size_t i = begin; i < end; ++i) {
    const Body& body = *bodies_[i];
    const btTransform& t = body.rb->getCenterOfMassTransform();
    for (std::size_t k = 0; k < body.geoms.size(); ++k) {
      const Geom& g = body.geoms[k];
      const std::size_t p = first_proxy_[i] + k;
      boxes_[p].off = !body.enabled;
      const btTransform offset(btQuaternion(g.offset[3], g.offset[4], g.offset[5], g.offset[6]),
                               btVector3(g.offset[0], g.offset[1], g.offset[2]));
      poses_[p].transform = t * offset;
      btVector3 lo, hi;
      g.shape->getAabb(poses_[p].transform, lo, hi);
      boxes_[p].min = fromBt(lo) - Vec3::Constant(margin);
      boxes_[p].max = fromBt(hi) + Vec3::Constant(margin);
    }
  }
}

void BulletEngine::narrowphase(Context& context, Chunk& chunk, int a, int b, double h) {
  // a: a proxy; b: a proxy, or -1 - plane index for a plane
  if (b >= 0 && proxies_[static_cast<std::size_t>(a)].body < 0) std::swap(a, b);  // a body's geom first
  const Proxy& pa = proxies_[static_cast<std::size_t>(a)];
  // nothing between two things that cannot move (static shapes and kinematic bodies)
  auto movable = [this](int body) { return body >= 0 && !bodies_[static_cast<std::size_t>(body)]->kinematic; };
  if (!movable(pa.body) && (b < 0 || !movable(proxies_[static_cast<std::size_t>(b)].body))) return;
  // nothing between bodies joined to each other
  if (b >= 0 && proxies_[static_cast<std::size_t>(b)].body >= 0 &&
      articulation_[static_cast<std::size_t>(pa.body)] ==
          articulation_[static_cast<std::size_t>(proxies_[static_cast<std::size_t>(b)].body)])
    return;
  // nor between an articulation and the static shapes it hangs from
  if (const int hangs = pa.body >= 0 ? hangs_from_[static_cast<std::size_t>(pa.body)] : -1; hangs >= 0) {
    const int stat = b < 0 ? planes_[static_cast<std::size_t>(-1 - b)]
                           : proxies_[static_cast<std::size_t>(b)].static_index;
    if (stat >= 0 && statics_[static_cast<std::size_t>(stat)]->group == hangs) return;
  }
  const btCollisionObject* object_b;
  const btCollisionShape* shape_b;
  const btTransform* pose_b;
  int part_b = 0;
  if (b < 0) {
    const StaticObject& plane = *statics_[static_cast<std::size_t>(planes_[static_cast<std::size_t>(-1 - b)])];
    object_b = plane.object.get();
    shape_b = plane.shape.get();
    pose_b = &plane.object->getWorldTransform();
  } else {
    const Proxy& pb = proxies_[static_cast<std::size_t>(b)];
    object_b = pb.object;
    shape_b = pb.shape;
    pose_b = &poses_[static_cast<std::size_t>(b)].transform;
    part_b = pb.part;
  }
  const btCollisionObjectWrapper wa(nullptr, pa.shape, pa.object, poses_[static_cast<std::size_t>(a)].transform, -1,
                                    pa.part);
  const btCollisionObjectWrapper wb(nullptr, shape_b, object_b, *pose_b, -1, part_b);
  // a new algorithm, with a new manifold of its own (Bullet's algorithms make their own): the
  // contacts of this substep only; both live until the substep is solved
  btCollisionAlgorithm* algorithm = context.dispatcher.findAlgorithm(&wa, &wb, nullptr, BT_CONTACT_POINT_ALGORITHMS);
  if (algorithm == nullptr) return;
  chunk.algorithms.push_back({algorithm, &context});
  btManifoldResult result(&wa, &wb);
  btDispatcherInfo info;
  info.m_timeStep = h;
  info.m_useContinuous = false;
  algorithm->processCollision(&wa, &wb, info, &result);
  btManifoldArray& found = *chunk.found;
  found.resize(0);
  algorithm->getAllContactManifolds(found);
  for (int m = 0; m < found.size(); ++m) {
    btPersistentManifold* manifold = found[m];
    // Bullet reports points up to 2 cm apart, which its solver uses speculatively: it lets the gap
    // close and no more. A body that would reach the surface within this substep is thereby
    // stopped at it, a substep before the impact, so it never bounces (restitution is lost). Such
    // a point is made a touching one: the impact, with its restitution, happens now, less than one
    // substep's travel early. Points the body does not reach within the substep stay speculative.
    const int n = manifold->getNumContacts();
    if (n == 0) continue;
    for (int k = 0; k < n; ++k) {
      btManifoldPoint& p = manifold->getContactPoint(k);
      bool touching = p.getDistance() <= 0;
      if (!touching) {
        const btVector3 closing = velocityAt(manifold->getBody1(), p.getPositionWorldOnB()) -
                                  velocityAt(manifold->getBody0(), p.getPositionWorldOnA());
        touching = closing.dot(p.m_normalWorldOnB) * h >= p.getDistance();
        if (touching) p.setDistance(0);
      }
      p.m_combinedFriction = settings_.friction;
      p.m_combinedRestitution = touching ? settings_.restitution : 0.0;  // (a speculative point only stops)
      p.m_combinedRollingFriction = 0;
      p.m_combinedSpinningFriction = 0;
    }
    chunk.manifolds.push_back(manifold);
  }
}

void BulletEngine::releaseContacts() {
  // each algorithm back to the dispatcher that made it (its manifold with it), one at a time: a
  // dispatcher's pools are not shared between threads
  for (Chunk& chunk : chunks_) {
    for (const auto& [algorithm, context] : chunk.algorithms) {
      algorithm->~btCollisionAlgorithm();
      context->dispatcher.freeCollisionAlgorithm(algorithm);
    }
    chunk.algorithms.clear();
    chunk.manifolds.clear();
  }
}

void BulletEngine::collide(double h) {
  if (proxies_stale_) indexGeoms();
  forEach((bodies_.size() + kBodiesPerChunk - 1) / kBodiesPerChunk, [&](std::size_t c) {
    placeGeoms(c * kBodiesPerChunk, std::min(bodies_.size(), (c + 1) * kBodiesPerChunk));
  });
  grid_.build(boxes_, cell_);
  const std::size_t grid_chunks = grid_.chunkCount();
  const std::size_t plane_chunks =
      planes_.empty() ? 0 : (dynamic_proxies_ + kGeomsPerPlaneChunk - 1) / kGeomsPerPlaneChunk;
  if (chunks_.size() < grid_chunks + plane_chunks) {
    const std::size_t had = chunks_.size();
    chunks_.resize(grid_chunks + plane_chunks);
    for (std::size_t c = had; c < chunks_.size(); ++c) {
      chunks_[c].pairs.reserve(256);
      chunks_[c].algorithms.reserve(c < plane_chunks ? kGeomsPerPlaneChunk : 256);
      chunks_[c].manifolds.reserve(c < plane_chunks ? kGeomsPerPlaneChunk : 256);
      chunks_[c].found = std::make_shared<btManifoldArray>();
      chunks_[c].found->reserve(4);
    }
  }
  const double threshold = gContactBreakingThreshold;
  forEach(grid_chunks + plane_chunks, [&](std::size_t c) {
    Chunk& chunk = chunks_[c];
    const Lease lease(*this);
    Context& context = lease.context();
    if (c < plane_chunks) {
      const std::size_t begin = c * kGeomsPerPlaneChunk;
      const std::size_t end = std::min(dynamic_proxies_, begin + kGeomsPerPlaneChunk);
      for (std::size_t k = begin; k < end; ++k) {
        const GridBroadphase::Box& box = boxes_[k];
        if (box.off) continue;
        const Vec3 centre = (box.min + box.max) / 2;
        const Vec3 half = (box.max - box.min) / 2;
        for (std::size_t p = 0; p < planes_.size(); ++p) {
          const StaticObject& plane = *statics_[static_cast<std::size_t>(planes_[p])];
          const double gap = plane.normal.dot(centre) - plane.normal.cwiseAbs().dot(half) - plane.offset;
          if (gap > threshold) continue;
          narrowphase(context, chunk, static_cast<int>(k), -1 - static_cast<int>(p), h);
        }
      }
      return;
    }
    chunk.pairs.clear();
    grid_.pairs(c - plane_chunks, chunk.pairs);
    for (const auto& [a, b] : chunk.pairs) narrowphase(context, chunk, a, b, h);
  });
  manifolds_.clear();
  for (std::size_t c = 0; c < grid_chunks + plane_chunks; ++c)
    manifolds_.insert(manifolds_.end(), chunks_[c].manifolds.begin(), chunks_[c].manifolds.end());
}

void BulletEngine::buildIslands() {
  // union-find over the bodies that touch each other (the smallest index as the root)
  auto find = [this](int x) { return groups_.find(x); };
  auto bodyOf = [](const btCollisionObject* o) { return o->getUserIndex(); };
  // a manifold's body: a dynamic one of its two objects (the other may be static)
  auto ownerOf = [&](const btPersistentManifold* m) {
    const int a = bodyOf(m->getBody0());
    return a >= 0 ? a : bodyOf(m->getBody1());
  };
  // joined bodies are one island, contacts or not
  // (a joint of bodies out of the world holds nothing: the world takes out whole articulations)
  const auto holds = [this](const Joint& j) {
    return !j.removed && bodies_[static_cast<std::size_t>(j.spec.child)]->enabled;
  };
  for (const Joint& j : joints_) {
    if (!holds(j)) continue;
    if (j.spec.parent >= 0)
      groups_.unite(j.spec.child, j.spec.parent);
    else
      (void)find(j.spec.child);
  }
  for (const btPersistentManifold* m : manifolds_) {
    const int a = bodyOf(m->getBody0());
    const int b = bodyOf(m->getBody1());
    if (a >= 0 && b >= 0)
      groups_.unite(a, b);
    else
      (void)find(a >= 0 ? a : b);
  }
  // islands in the order of their lowest body; bodies ascending, manifolds in pair order
  std::vector<std::pair<int, int>>& members = members_;  // (root, body)
  members.clear();
  for (const int i : groups_.touched()) members.emplace_back(find(i), i);
  std::sort(members.begin(), members.end());
  islands_.clear();
  island_bodies_.clear();
  for (std::size_t k = 0; k < members.size(); ++k) {
    if (k == 0 || members[k].first != members[k - 1].first)
      islands_.push_back({members[k].first, island_bodies_.size(), 0, 0, 0, 0, 0});
    island_bodies_.push_back(bodies_[static_cast<std::size_t>(members[k].second)]->rb.get());
    ++islands_.back().bodies;
  }
  std::vector<std::pair<int, std::size_t>>& order = manifold_order_;  // (root, manifold index)
  order.clear();
  for (std::size_t k = 0; k < manifolds_.size(); ++k) order.emplace_back(find(ownerOf(manifolds_[k])), k);
  std::sort(order.begin(), order.end());
  island_manifolds_.clear();
  std::size_t island = 0;
  for (const auto& [root, k] : order) {
    while (islands_[island].root != root) ++island;
    if (islands_[island].manifolds == 0) islands_[island].first_manifold = island_manifolds_.size();
    island_manifolds_.push_back(manifolds_[k]);
    ++islands_[island].manifolds;
  }
  // the joints of each island, in the order they were added
  joint_order_.clear();
  for (std::size_t k = 0; k < joints_.size(); ++k)
    if (holds(joints_[k])) joint_order_.emplace_back(find(joints_[k].spec.child), k);
  std::sort(joint_order_.begin(), joint_order_.end());
  island_joints_.clear();
  island = 0;
  for (const auto& [root, k] : joint_order_) {
    while (islands_[island].root != root) ++island;
    if (islands_[island].joints == 0) islands_[island].first_joint = island_joints_.size();
    island_joints_.push_back(joints_[k].constraint.get());
    ++islands_[island].joints;
  }
  free_bodies_.clear();
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (!groups_.grouped(static_cast<int>(i)) && bodies_[i]->enabled) free_bodies_.push_back(bodies_[i]->rb.get());
  groups_.clear();
}

}  // namespace ssx::detail
