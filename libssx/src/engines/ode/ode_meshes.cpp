// Mesh shapes on ODE: a moving body's mesh as its convex hull (dCreateConvex, which collides with
// every primitive, other hulls and triangle meshes), a static one as its triangles (dCreateTriMesh).
// ODE reads the arrays it is given while the geom lives: OdeMeshes keeps them, one set per mesh.
#include "engines/ode/ode_engine.hpp"

namespace ssx::detail {

OdeMeshes::~OdeMeshes() {
  for (auto& [mesh, t] : triangles_) dGeomTriMeshDataDestroy(t.data);
}

dGeomID OdeMeshes::create(const Shape& s, bool is_static, Vec3& centre) {
  const TriangleMesh& m = *s.mesh;
  centre = Vec3::Zero();
  if (is_static) {
    auto [it, fresh] = triangles_.try_emplace(&m);
    Triangles& t = it->second;
    if (fresh) {
      t.mesh = s.mesh;
      t.indices.assign(m.triangles.begin(), m.triangles.end());
      t.data = dGeomTriMeshDataCreate();
      dGeomTriMeshDataBuildDouble(t.data, m.vertices.data()->data(), sizeof(Vec3), static_cast<int>(m.vertices.size()),
                                  t.indices.data(), static_cast<int>(t.indices.size()), 3 * sizeof(dTriIndex));
    }
    return dCreateTriMesh(nullptr, t.data, nullptr, nullptr, nullptr);
  }
  auto [it, fresh] = hulls_.try_emplace(&m);
  Hull& h = it->second;
  if (fresh) {
    h.mesh = s.mesh;
    const auto& corners = m.hull_vertices;
    for (const Vec3& v : corners) h.centre += v;
    h.centre /= static_cast<double>(corners.size());  // inside: a hull of a solid has no two-dimensional corner set
    for (const Vec3& v : corners) {
      const Vec3 p = v - h.centre;
      h.points.insert(h.points.end(), {p.x(), p.y(), p.z()});
    }
    const auto& tri = m.hull_triangles;
    for (std::size_t i = 0; i + 2 < tri.size(); i += 3) {
      const Vec3 a = corners[tri[i]] - h.centre, b = corners[tri[i + 1]] - h.centre, c = corners[tri[i + 2]] - h.centre;
      const Vec3 n = (b - a).cross(c - a).normalized();
      h.planes.insert(h.planes.end(), {n.x(), n.y(), n.z(), n.dot(a)});
      h.polygons.insert(h.polygons.end(), {3u, tri[i], tri[i + 1], tri[i + 2]});
    }
  }
  centre = h.centre;
  return dCreateConvex(nullptr, h.planes.data(), static_cast<unsigned>(h.planes.size() / 4), h.points.data(),
                       static_cast<unsigned>(h.points.size() / 3), h.polygons.data());
}

}  // namespace ssx::detail
