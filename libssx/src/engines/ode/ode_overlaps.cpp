// findShapeOverlaps (shape_overlaps.hpp) with ODE's collision library: every shape a geom, the
// candidate pairs from ssx's grid broadphase, each through dCollide. Used once, when a scene is
// built.

#include "engines/shape_overlaps.hpp"

#include "engines/grid_broadphase.hpp"
#include "engines/ode/ode_engine.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace ssx::detail {

namespace {

dGeomID makeGeom(const PosedShape& s, OdeMeshes& meshes) {
  const Shape& shape = *s.shape;
  if (shape.kind == Shape::Kind::Plane) {
    const Vec3 n = s.world.orientation * Vec3::UnitZ();
    return dCreatePlane(nullptr, n.x(), n.y(), n.z(), n.dot(s.world.position));
  }
  // (a mesh: its hull on a moving body, its triangles on a static one, as the engine steps them)
  Vec3 centre;
  dGeomID g = createOdeGeom(shape, meshes, s.is_static, centre);
  const Quat& q = s.world.orientation;
  const dQuaternion oq = {q.w(), q.x(), q.y(), q.z()};
  const Vec3 at = s.world.transformPoint(centre);
  dGeomSetPosition(g, at.x(), at.y(), at.z());
  dGeomSetQuaternion(g, oq);
  return g;
}

// the geoms of the shapes, destroyed with it
struct Geoms {
  OdeMeshes meshes;  // (destroyed after the geoms)
  std::vector<dGeomID> ids;
  ~Geoms() {
    for (dGeomID g : ids) dGeomDestroy(g);
  }
};

}  // namespace

std::vector<ShapeOverlap> findShapeOverlaps(std::span<const PosedShape> shapes, double min_depth) {
  if (shapes.empty()) return {};
  // candidate pairs from the shapes' bounding boxes (the engine's broadphase: linear in the
  // shapes), then ODE's narrowphase for each
  std::vector<ShapeOverlap> out;
  acquireOde();
  try {
    ensureThreadData();
    Geoms geoms;
    geoms.ids.reserve(shapes.size());
    std::vector<GridBroadphase::Box> boxes(shapes.size());
    std::vector<double> sizes;
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      geoms.ids.push_back(makeGeom(shapes[i], geoms.meshes));
      dReal aabb[6];
      dGeomGetAABB(geoms.ids.back(), aabb);
      boxes[i].min = Vec3(aabb[0], aabb[2], aabb[4]);
      boxes[i].max = Vec3(aabb[1], aabb[3], aabb[5]);
      boxes[i].owner = shapes[i].is_static ? -1 : static_cast<int>(shapes[i].owner);
      const double size = (boxes[i].max - boxes[i].min).norm();
      if (std::isfinite(size)) sizes.push_back(size);
    }
    double cell = 1.0;
    if (!sizes.empty()) {
      std::nth_element(sizes.begin(), sizes.begin() + static_cast<std::ptrdiff_t>(sizes.size() / 2), sizes.end());
      cell = std::max(2 * sizes[sizes.size() / 2], 1e-3);
    }
    GridBroadphase grid;
    grid.build(boxes, cell);
    std::vector<std::pair<int, int>> pairs;
    for (std::size_t c = 0; c < grid.chunkCount(); ++c) grid.pairs(c, pairs);
    std::map<std::pair<std::size_t, std::size_t>, ShapeOverlap> deepest;  // by owner pair
    constexpr int kMaxContacts = 8;
    dContactGeom contacts[kMaxContacts];
    for (auto [a, b] : pairs) {
      auto i = static_cast<std::size_t>(a);
      auto j = static_cast<std::size_t>(b);
      if (j < i) std::swap(i, j);
      // a static shape's owner is an artifact too: two static shapes of different artifacts
      // never pair (owner -1), one artifact's never either
      if (shapes[i].owner == shapes[j].owner || (shapes[i].is_static && shapes[j].is_static)) continue;
      const int n = dCollide(geoms.ids[i], geoms.ids[j], kMaxContacts, contacts, sizeof(dContactGeom));
      for (int k = 0; k < n; ++k) {
        const dContactGeom& c = contacts[k];
        if (!std::isfinite(c.depth) || c.depth <= min_depth) continue;
        const ShapeOverlap found{i, j, c.depth, Vec3(c.pos[0], c.pos[1], c.pos[2])};
        auto [it, fresh] = deepest.try_emplace(std::minmax(shapes[i].owner, shapes[j].owner), found);
        if (!fresh &&
            (c.depth > it->second.depth ||
             (c.depth == it->second.depth && std::pair(i, j) < std::pair(it->second.first, it->second.second))))
          it->second = found;
      }
    }
    out.reserve(deepest.size());
    for (const auto& [owners, overlap] : deepest) out.push_back(overlap);
  } catch (...) {
    releaseOde();
    throw;
  }
  releaseOde();
  std::sort(out.begin(), out.end(), [](const ShapeOverlap& a, const ShapeOverlap& b) {
    return std::pair(a.first, a.second) < std::pair(b.first, b.second);
  });
  return out;
}

}  // namespace ssx::detail
