// Ray queries (Environment::castRays): the engine's, against its shapes posed where the snapshot
// has the bodies (re-posed after each step's physics when enabled, or before a query between steps
// after the bodies were moved).
#include "world/phase_guard.hpp"
#include "world/world.hpp"

#include <ssx/environment.hpp>

namespace ssx {

void Environment::enableRayQueries() {
  if (detail::PhaseGuard::now.in_phase)
    throw Error("enableRayQueries is not allowed in the parallel phases: call it from configure");
  rays_enabled_ = true;
  rays_stale_ = true;
}

void Environment::castRays(std::span<const Ray> rays, std::span<RayHit> hits, const Artifact* ignore) const {
  if (!rays_enabled_) throw Error("castRays: ray queries are not enabled (enableRayQueries, from a plugin's configure)");
  if (world_->state != State::Running) throw Error("castRays: the environment is not running");
  if (rays.size() != hits.size()) throw Error("castRays: one hit per ray");
  if (rays_stale_) {
    // (only ever between steps: after a step's physics the shapes are posed before the sensors run)
    if (detail::PhaseGuard::now.in_phase) throw Error("castRays: the shapes were not posed for this step");
    physics_->prepareRayQueries();
    rays_stale_ = false;
  }
  int begin = 0, end = 0;
  if (ignore != nullptr) {
    const detail::ArtifactData& a = world_->data(*ignore);
    begin = a.body_begin;
    end = a.body_end;
  }
  physics_->castRays(rays, hits, begin, end);
}

}  // namespace ssx
