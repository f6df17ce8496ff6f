// The ODE engine's collision: geoms placed and boxed, the grid broadphase, contacts found in
// parallel chunks and joined in a fixed order, and bodies in contact grouped into one world.
#include "engines/ode/ode_engine.hpp"

#include <ssx/error.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace ssx::detail {

void OdeEngine::placeGeoms(std::size_t begin, std::size_t end) {
  // what ODE's dxGeom::computePosr does for a geom offset from its body, bit for bit
  for (std::size_t i = begin; i < end; ++i) {
    const Body& body = bodies_[i];
    if (body.geoms.empty()) continue;
    for (std::size_t k = 0; k < body.geoms.size(); ++k) boxes_[first_proxy_[i] + k].off = !body.enabled;
    const dReal* p = dBodyGetPosition(body.id);
    const dReal* r = dBodyGetRotation(body.id);
    for (std::size_t k = 0; k < body.geoms.size(); ++k) {
      const Geom& g = body.geoms[k];
      dVector3 position;
      dMatrix3 rotation;
      dMultiply0_331(position, r, g.offset_position);
      position[0] += p[0];
      position[1] += p[1];
      position[2] += p[2];
      dMultiply0_333(rotation, r, g.offset_rotation);
      dGeomSetPosition(g.id, position[0], position[1], position[2]);
      dGeomSetRotation(g.id, rotation);
      dReal aabb[6];
      dGeomGetAABB(g.id, aabb);
      GridBroadphase::Box& box = boxes_[first_proxy_[i] + k];
      box.min = Vec3(aabb[0], aabb[2], aabb[4]);
      box.max = Vec3(aabb[1], aabb[3], aabb[5]);
    }
  }
}

bool OdeEngine::aboveOf(const GridBroadphase::Box& box, const std::array<double, 4>& plane) {
  // the box's corner deepest along the plane's normal, still in front of it by more than rounding
  // could move a shape (dCollide would find no contact: skipping it changes nothing)
  double lowest = -plane[3];
  for (std::size_t k = 0; k < 3; ++k) {
    const int axis = static_cast<int>(k);
    lowest += plane[k] * (plane[k] > 0 ? box.min[axis] : box.max[axis]);
  }
  return lowest > 1e-6 * (1.0 + std::abs(plane[3]));
}

void OdeEngine::indexGeoms() {
  // the grid's boxes: the bodies' geoms in body order, then the static ones but the planes
  proxies_stale_ = false;
  proxy_geoms_.clear();
  boxes_.clear();
  first_proxy_.assign(bodies_.size(), 0);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    first_proxy_[i] = static_cast<std::uint32_t>(proxy_geoms_.size());
    for (const Geom& g : bodies_[i].geoms) {
      proxy_geoms_.push_back(g.id);
      boxes_.push_back({Vec3::Zero(), Vec3::Zero(), static_cast<int>(i)});
    }
  }
  dynamic_proxies_ = proxy_geoms_.size();
  std::vector<double> diameters;
  for (const Body& b : bodies_)
    for (const Geom& g : b.geoms) diameters.push_back(g.diameter);
  if (!diameters.empty()) {
    // a box longer than a cell is tested against every box: the cell holds the largest moving
    // geom (a TurtleBot's chassis is 4 times its wheel: with 10,000 of them, twice the median made
    // every chassis such a box, 70 % of a step), but no more than 8 times the median (one large
    // payload among small robots would make bands that hold too many)
    auto middle = diameters.begin() + static_cast<std::ptrdiff_t>(diameters.size() / 2);
    std::nth_element(diameters.begin(), middle, diameters.end());
    const double largest = *std::max_element(middle, diameters.end());
    cell_ = std::max(std::clamp(largest, 2.0 * *middle, 8.0 * *middle), 1e-3);
  }
  // room for what a step usually needs, so that steps do not allocate: every body resting on
  // something with a few contacts, a contact group's bookkeeping for every body
  contacts_.reserve(4 * bodies_.size() + 64);
  groups_.reserve(bodies_.size());
  away_.reserve(bodies_.size());
  for (dGeomID g : static_geoms_) {
    if (dGeomGetClass(g) == dPlaneClass) continue;
    dReal aabb[6];
    dGeomGetAABB(g, aabb);
    proxy_geoms_.push_back(g);
    boxes_.push_back({Vec3(aabb[0], aabb[2], aabb[4]), Vec3(aabb[1], aabb[3], aabb[5]), -1});
  }
}


void OdeEngine::collidePair(dGeomID a, dGeomID b, std::vector<dContact>& out, std::vector<dContact>& scratch) const {
  // nothing between two things that cannot move (static shapes and kinematic bodies)
  auto movable = [this](dGeomID g) {
    const auto owner = reinterpret_cast<std::intptr_t>(dGeomGetData(g));
    return owner > 0 && !bodies_[static_cast<std::size_t>(owner - 1)].kinematic;
  };
  if (!movable(a) && !movable(b)) return;
  // nothing between bodies joined to each other, nor between an articulation and the static
  // shapes it hangs from
  const auto owner_a = reinterpret_cast<std::intptr_t>(dGeomGetData(a));
  const auto owner_b = reinterpret_cast<std::intptr_t>(dGeomGetData(b));
  if (owner_a > 0 && owner_b > 0 &&
      articulation_[static_cast<std::size_t>(owner_a - 1)] == articulation_[static_cast<std::size_t>(owner_b - 1)])
    return;
  if ((owner_a > 0) != (owner_b > 0)) {
    const auto body = static_cast<std::size_t>(std::max(owner_a, owner_b) - 1);
    const auto group = static_cast<int>(-1 - std::min(owner_a, owner_b));
    if (hangs_from_[body] == group) return;
  }
  const int n = dCollide(a, b, static_cast<int>(scratch.size()), &scratch[0].geom, sizeof(dContact));
  const PhysicsSettings& s = settings_;
  for (int i = 0; i < n; ++i) {
    dContact c = scratch[static_cast<std::size_t>(i)];
    // ODE's narrowphase can report a contact with no direction (two cylinders touching along a
    // line give a zero normal): its solver would fail on it inside the step, so it is dropped
    const dContactGeom& g = c.geom;
    const double length2 = g.normal[0] * g.normal[0] + g.normal[1] * g.normal[1] + g.normal[2] * g.normal[2];
    if (!(length2 > 0.5 && length2 < 2.0) || !std::isfinite(g.depth) || !std::isfinite(g.pos[0]) ||
        !std::isfinite(g.pos[1]) || !std::isfinite(g.pos[2]))
      continue;
    c.surface.mode = dContactApprox1 | dContactSoftCFM | dContactSoftERP;
    c.surface.mu = s.friction;
    c.surface.soft_cfm = s.ode.contact_soft_cfm;
    c.surface.soft_erp = s.ode.contact_soft_erp;
    if (s.restitution > 0) {
      c.surface.mode |= dContactBounce;
      c.surface.bounce = s.restitution;
      c.surface.bounce_vel = 0.01;
    }
    out.push_back(c);
  }
}

void OdeEngine::collide() {
  contacts_.clear();
  if (proxies_stale_) indexGeoms();
  // pose the geoms, in chunks of bodies
  constexpr std::size_t kBodiesPerChunk = 256;
  forEach((bodies_.size() + kBodiesPerChunk - 1) / kBodiesPerChunk, [&](std::size_t c) {
    placeGeoms(c * kBodiesPerChunk, std::min(bodies_.size(), (c + 1) * kBodiesPerChunk));
  });
  // (one box cannot overlap another: a world of one robot over the ground builds no grid)
  if (boxes_.size() > 1) grid_.build(boxes_, cell_);
  // pairs and their contacts, in chunks: the dynamic geoms against each plane (their number
  // fixed by the scene: each chunk keeps the room it needs), then the grid's
  constexpr std::size_t kGeomsPerPlaneChunk = 512;
  const std::size_t grid_chunks = boxes_.size() > 1 ? grid_.chunkCount() : 0;
  const std::size_t plane_chunks =
      planes_.empty() ? 0 : (dynamic_proxies_ + kGeomsPerPlaneChunk - 1) / kGeomsPerPlaneChunk;
  if (chunks_.size() < grid_chunks + plane_chunks) {
    const std::size_t had = chunks_.size();
    chunks_.resize(grid_chunks + plane_chunks);
    for (std::size_t c = had; c < chunks_.size(); ++c) {
      chunks_[c].scratch.resize(contacts_per_pair_);
      chunks_[c].pairs.reserve(c < plane_chunks ? 0 : 256);
      // (a plane chunk: four contacts for each of its geoms, a box resting on a face)
      const std::size_t plane_geoms =
          c < plane_chunks ? std::min(kGeomsPerPlaneChunk, dynamic_proxies_ - c * kGeomsPerPlaneChunk) : 0;
      chunks_[c].contacts.reserve(c < plane_chunks ? 4 * plane_geoms : 64);
    }
  }
  forEach(grid_chunks + plane_chunks, [&](std::size_t c) {
    Chunk& chunk = chunks_[c];
    chunk.contacts.clear();
    if (c < plane_chunks) {
      const std::size_t begin = c * kGeomsPerPlaneChunk;
      const std::size_t end = std::min(dynamic_proxies_, begin + kGeomsPerPlaneChunk);
      for (std::size_t k = begin; k < end; ++k)
        for (std::size_t p = 0; p < planes_.size(); ++p)
          if (!boxes_[k].off && !aboveOf(boxes_[k], planes_params_[p]))
            collidePair(proxy_geoms_[k], planes_[p], chunk.contacts, chunk.scratch);
      return;
    }
    chunk.pairs.clear();
    grid_.pairs(c - plane_chunks, chunk.pairs);
    for (const auto& [a, b] : chunk.pairs)
      collidePair(proxy_geoms_[static_cast<std::size_t>(a)], proxy_geoms_[static_cast<std::size_t>(b)], chunk.contacts,
                  chunk.scratch);
  });
  for (std::size_t c = 0; c < grid_chunks + plane_chunks; ++c)
    contacts_.insert(contacts_.end(), chunks_[c].contacts.begin(), chunks_[c].contacts.end());

  // contact groups: union-find over the bodies that touch each other (a pinned body as the root
  // if there is one, else the lowest)
  for (const dContact& c : contacts_) {
    const auto owner_a = reinterpret_cast<std::intptr_t>(dGeomGetData(c.geom.g1));
    const auto owner_b = reinterpret_cast<std::intptr_t>(dGeomGetData(c.geom.g2));
    if (owner_a <= 0 || owner_b <= 0) continue;
    groups_.unite(static_cast<int>(owner_a - 1), static_cast<int>(owner_b - 1),
                  [this](int ra, int rb) { return firstOf(ra, rb); });
  }
}

void OdeEngine::groupContacts() {
  // an articulation lies in one world: the groups its bodies touch are one group
  const auto first = [this](int ra, int rb) { return firstOf(ra, rb); };
  const std::size_t touched = groups_.touched().size();
  for (std::size_t k = 0; k < touched; ++k) {
    const int i = groups_.touched()[k];
    if (bodies_[static_cast<std::size_t>(i)].pinned)
      groups_.unite(i, articulation_[static_cast<std::size_t>(i)], first);
  }
  // where each body steps this substep: a body in contact with others in the home world of the
  // group's root (a pinned body's when there is one), every other body at home; an articulation
  // moves whole, its joints with it
  for (const int i : groups_.touched()) {
    Body& body = bodies_[static_cast<std::size_t>(i)];
    const int target = bodies_[static_cast<std::size_t>(groups_.rootOf(i))].home;
    if (body.partition == target) continue;
    if (body.pinned) {
      relocate(articulation_[static_cast<std::size_t>(i)], target);
      continue;
    }
    if (target != body.home) listAway(i);
    moveBody(i, target);
  }
  // the bodies away from home whose group no longer needs them there go back, lowest first (an
  // articulation when none of its bodies is in a group)
  std::sort(away_.begin(), away_.end());
  std::size_t kept = 0;
  for (std::size_t k = 0, n = away_.size(); k < n; ++k) {
    const int i = away_[k];
    Body& body = bodies_[static_cast<std::size_t>(i)];
    if (body.partition == body.home) {  // (a group brought it home, or its articulation went)
      body.listed = false;
      continue;
    }
    bool needed = groups_.grouped(i);
    if (body.pinned)
      for (const int m : membersOf(articulation_[static_cast<std::size_t>(i)])) needed = needed || groups_.grouped(m);
    if (needed) {
      away_[kept++] = i;
      continue;
    }
    body.listed = false;
    if (body.pinned)
      relocate(articulation_[static_cast<std::size_t>(i)], body.home);
    else
      moveBody(i, body.home);
  }
  away_.resize(kept);
  groups_.clear();
}

}  // namespace ssx::detail
