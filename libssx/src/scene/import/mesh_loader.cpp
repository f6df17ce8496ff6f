// Meshes from files (assimp: STL, OBJ, COLLADA and the rest it reads) and their convex hulls
// (Bullet's btConvexHullComputer, from its LinearMath), with the hull's volume, centroid and
// inertia for a body's mass.
#include "scene/import/mesh_loader.hpp"

#include <ssx/error.hpp>

#include <LinearMath/btConvexHullComputer.h>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <chrono>
#include <cmath>

namespace ssx {

namespace {

// volume, first and second moments of a closed surface by its tetrahedra from the origin
// (divergence theorem); the surface's triangles counter-clockwise seen from outside
struct Moments {
  double volume = 0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();  // integral of r r^T over the volume
};

Moments moments(const std::vector<Vec3>& v, const std::vector<std::uint32_t>& tri) {
  Moments m;
  for (std::size_t i = 0; i + 2 < tri.size(); i += 3) {
    const Vec3 &a = v[tri[i]], &b = v[tri[i + 1]], &c = v[tri[i + 2]];
    const double det = a.dot(b.cross(c));  // six times the signed volume of (0, a, b, c)
    m.volume += det / 6.0;
    m.first += det / 24.0 * (a + b + c);
    // the integral of r r^T over a tetrahedron with one corner at the origin
    const Vec3 s = a + b + c;
    m.second += det / 120.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  return m;
}

}  // namespace

void TriangleMesh::computeHull() {
  if (vertices.empty()) throw Error("mesh '" + file + "' has no vertices");
  min = max = vertices[0];
  for (const Vec3& p : vertices) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  btConvexHullComputer hull;
  hull.compute(vertices.data()->data(), static_cast<int>(sizeof(Vec3)), static_cast<int>(vertices.size()), 0.0, 0.0);
  hull_vertices.clear();
  hull_triangles.clear();
  for (int i = 0; i < hull.vertices.size(); ++i)
    hull_vertices.emplace_back(hull.vertices[i].x(), hull.vertices[i].y(), hull.vertices[i].z());
  for (int f = 0; f < hull.faces.size(); ++f) {
    // each face is a convex polygon, its edges counter-clockwise: a fan of triangles
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const int a = first->getSourceVertex();
    const btConvexHullComputer::Edge* e = first->getNextEdgeOfFace();
    for (; e->getTargetVertex() != a; e = e->getNextEdgeOfFace()) {
      hull_triangles.push_back(static_cast<std::uint32_t>(a));
      hull_triangles.push_back(static_cast<std::uint32_t>(e->getSourceVertex()));
      hull_triangles.push_back(static_cast<std::uint32_t>(e->getTargetVertex()));
    }
  }
  const Moments m = moments(hull_vertices, hull_triangles);
  const double size = (max - min).norm();
  if (hull_triangles.size() < 12 || !(m.volume > 1e-12 * size * size * size) || !(m.volume > 0))
    throw Error("mesh '" + file + "' encloses no volume (its points lie in a plane or a line): a moving body "
                "cannot collide as it or weigh it; give the link a box or another primitive");
  hull_volume = m.volume;
  hull_centroid = m.first / m.volume;
  // about the centroid, per unit mass: trace(S) I - S, S the second moment about the centroid
  const Mat3 s = m.second / m.volume - hull_centroid * hull_centroid.transpose();
  hull_unit_inertia = s.trace() * Mat3::Identity() - s;
}

namespace detail {

std::shared_ptr<const TriangleMesh> MeshCache::load(const fs::path& file, const Vec3& scale, std::string& problem) {
  const auto key = std::make_tuple(file.string(), scale.x(), scale.y(), scale.z());
  if (const auto it = meshes_.find(key); it != meshes_.end()) return it->second;
  const auto start = std::chrono::steady_clock::now();
  Assimp::Importer importer;
  // the file's own axes, as URDF and SDF take them (no conversion to assimp's y-up)
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const aiScene* scene = importer.ReadFile(
      file.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                         aiProcess_SortByPType | aiProcess_DropNormals);
  if (scene == nullptr) {
    problem = std::string("cannot read it: ") + importer.GetErrorString();
    return nullptr;
  }
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->file = file.string();
  mesh->scale = scale;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& in = *scene->mMeshes[m];
    if ((in.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;  // points and lines have no surface
    const auto base = static_cast<std::uint32_t>(mesh->vertices.size());
    for (unsigned i = 0; i < in.mNumVertices; ++i)
      mesh->vertices.emplace_back(scale.x() * in.mVertices[i].x, scale.y() * in.mVertices[i].y,
                                  scale.z() * in.mVertices[i].z);
    for (unsigned f = 0; f < in.mNumFaces; ++f) {
      const aiFace& face = in.mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (unsigned k = 0; k < 3; ++k) mesh->triangles.push_back(base + face.mIndices[k]);
    }
  }
  // a mirroring scale turns the triangles inside out: turn them back
  if (scale.prod() < 0)
    for (std::size_t i = 0; i + 2 < mesh->triangles.size(); i += 3) std::swap(mesh->triangles[i + 1], mesh->triangles[i + 2]);
  for (const Vec3& p : mesh->vertices)
    if (!p.allFinite()) {
      problem = "it has a vertex that is not a finite number";
      return nullptr;
    }
  if (mesh->triangles.empty()) {
    problem = "it holds no triangles";
    return nullptr;
  }
  try {
    mesh->computeHull();
  } catch (const Error& e) {
    // drawn all the same; a body's shape needs the hull (SceneLoader::readMesh says so)
    mesh->hull_vertices.clear();
    mesh->hull_triangles.clear();
  }
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  meshes_.emplace(key, mesh);
  return mesh;
}

}  // namespace detail

}  // namespace ssx
