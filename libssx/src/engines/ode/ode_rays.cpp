// The ODE engine's ray queries: each ray is an ODE ray geom collided (dCollide) with the shapes the
// grid finds along it and with the planes, the nearest hit kept.
#include "engines/ode/ode_engine.hpp"

#include <mutex>

namespace ssx::detail {

void OdeEngine::prepareRayQueries() {
  ensureThreadData();
  if (proxies_stale_) indexGeoms();
  constexpr std::size_t kBodiesPerChunk = 256;
  forEach((bodies_.size() + kBodiesPerChunk - 1) / kBodiesPerChunk, [&](std::size_t c) {
    placeGeoms(c * kBodiesPerChunk, std::min(bodies_.size(), (c + 1) * kBodiesPerChunk));
  });
  grid_.build(boxes_, cell_);
}

void OdeEngine::castRays(std::span<const Ray> rays, std::span<RayHit> hits, int ignore_begin, int ignore_end) const {
  ensureThreadData();
  dGeomID ray = nullptr;
  {
    std::lock_guard lock(rays_mutex_);
    if (!free_rays_.empty()) {
      ray = free_rays_.back();
      free_rays_.pop_back();
    }
  }
  if (ray == nullptr) ray = dCreateRay(nullptr, 1.0);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Vec3 d = rays[i].to - rays[i].from;
    const double length = d.norm();
    RayHit best;
    if (length > 0) {
      const Vec3 u = d / length;
      dGeomRaySetLength(ray, length);
      dGeomRaySet(ray, rays[i].from.x(), rays[i].from.y(), rays[i].from.z(), u.x(), u.y(), u.z());
      auto test = [&](dGeomID g, int body) {
        dContactGeom c;
        if (dCollide(ray, g, 1, &c, sizeof c) != 1 || !(c.depth < best.distance)) return;
        best.hit = true;
        best.distance = c.depth;
        best.point = Vec3(c.pos[0], c.pos[1], c.pos[2]);
        best.normal = Vec3(c.normal[0], c.normal[1], c.normal[2]);
        best.body = body;
      };
      grid_.overlapping(rays[i].from.cwiseMin(rays[i].to), rays[i].from.cwiseMax(rays[i].to), [&](int box) {
        const int body = boxes_[static_cast<std::size_t>(box)].owner;
        if (body >= ignore_begin && body < ignore_end) return;
        test(proxy_geoms_[static_cast<std::size_t>(box)], body);
      });
      for (dGeomID plane : planes_) test(plane, -1);
    }
    hits[i] = best;
  }
  std::lock_guard lock(rays_mutex_);
  free_rays_.push_back(ray);
}

}  // namespace ssx::detail
