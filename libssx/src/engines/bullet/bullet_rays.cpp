// The Bullet engine's ray queries: Bullet's single-object ray test (btCollisionWorld::rayTestSingle)
// against the shapes the grid finds along each ray and against the planes, the nearest hit kept.
#include "engines/bullet/bullet_parts.hpp"

namespace ssx::detail {

using namespace bullet;

void BulletEngine::prepareRayQueries() {
  if (proxies_stale_) indexGeoms();
  forEach((bodies_.size() + kBodiesPerChunk - 1) / kBodiesPerChunk, [&](std::size_t c) {
    placeGeoms(c * kBodiesPerChunk, std::min(bodies_.size(), (c + 1) * kBodiesPerChunk));
  });
  grid_.build(boxes_, cell_);
}

void BulletEngine::castRays(std::span<const Ray> rays, std::span<RayHit> hits, int ignore_begin, int ignore_end) const {
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const btVector3 from = toBt(rays[i].from), to = toBt(rays[i].to);
    const btTransform from_t(btQuaternion::getIdentity(), from), to_t(btQuaternion::getIdentity(), to);
    const double length = (rays[i].to - rays[i].from).norm();
    RayHit best;
    auto test = [&](btCollisionObject* object, const btCollisionShape* shape, const btTransform& pose, int body) {
      btCollisionWorld::ClosestRayResultCallback result(from, to);
      btCollisionWorld::rayTestSingle(from_t, to_t, object, shape, pose, result);
      if (!result.hasHit() || !(result.m_closestHitFraction * length < best.distance)) return;
      best.hit = true;
      best.distance = result.m_closestHitFraction * length;
      best.point = fromBt(result.m_hitPointWorld);
      best.normal = fromBt(result.m_hitNormalWorld.normalized());
      best.body = body;
    };
    if (length > 0) {
      grid_.overlapping(rays[i].from.cwiseMin(rays[i].to), rays[i].from.cwiseMax(rays[i].to), [&](int box) {
        const Proxy& p = proxies_[static_cast<std::size_t>(box)];
        if (p.body >= ignore_begin && p.body < ignore_end) return;
        test(p.object, p.shape, poses_[static_cast<std::size_t>(box)].transform, p.body);
      });
      for (const int k : planes_) {
        const StaticObject& plane = *statics_[static_cast<std::size_t>(k)];
        test(plane.object.get(), plane.shape.get(), plane.object->getWorldTransform(), -1);
      }
    }
    hits[i] = best;
  }
}

}  // namespace ssx::detail
