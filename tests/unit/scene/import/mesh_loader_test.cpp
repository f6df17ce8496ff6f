// Meshes read from files (mesh_loader.cpp): an OBJ cube and an L-shaped block read with assimp,
// scaled, their hulls' volume, centroid and inertia in closed form; what cannot be a body's shape
// (a flat mesh) or cannot be read at all is said.
#include "scene_util.hpp"

#include "scene/import/mesh_loader.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

using namespace ssx;
namespace fs = std::filesystem;

namespace {

fs::path writeObj(const std::string& name, const std::string& text) {
  const fs::path dir = fs::current_path() / "mesh_loader_test";
  fs::create_directories(dir);
  std::ofstream(dir / name) << text;
  return dir / name;
}

// an L of two unit cubes side by side plus one on top of the first, as an OBJ of quads
const char* kCube = R"(v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
)";

}  // namespace

TEST_CASE("a mesh read from a file: its hull's volume, centroid and inertia, scaled", "[import][mesh]") {
  detail::MeshCache cache;
  std::string problem;
  const auto cube = cache.load(writeObj("cube.obj", kCube), Vec3(2, 1, 1), problem);
  REQUIRE(cube != nullptr);
  CHECK(problem.empty());
  CHECK(cube->triangles.size() == 36);  // six quads, two triangles each
  CHECK(cube->hull_volume == Approx(2.0));
  CHECK(cube->hull_centroid.isApprox(Vec3(1, 0.5, 0.5)));
  // a 2 x 1 x 1 box: Ixx = (1 + 1) / 12, Iyy = Izz = (4 + 1) / 12 per kg
  CHECK(cube->hull_unit_inertia(0, 0) == Approx(2.0 / 12));
  CHECK(cube->hull_unit_inertia(1, 1) == Approx(5.0 / 12));
  CHECK(std::abs(cube->hull_unit_inertia(0, 1)) < 1e-12);
  CHECK(cube->max.isApprox(Vec3(2, 1, 1)));
  // read once per file and scale
  CHECK(cache.load(writeObj("cube.obj", kCube), Vec3(2, 1, 1), problem) == cube);
  CHECK(cache.load(writeObj("cube.obj", kCube), Vec3(1, 1, 1), problem) != cube);
  // mirrored, the triangles are turned back outward: the same volume
  const auto mirrored = cache.load(writeObj("cube.obj", kCube), Vec3(-1, 1, 1), problem);
  REQUIRE(mirrored != nullptr);
  CHECK(mirrored->hull_volume == Approx(1.0));
}

TEST_CASE("a flat mesh has no hull, and a file that is no mesh is said", "[import][mesh]") {
  detail::MeshCache cache;
  std::string problem;
  const auto flat = cache.load(writeObj("flat.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"), Vec3::Ones(), problem);
  REQUIRE(flat != nullptr);  // drawn, but no body's shape
  CHECK(flat->hull_triangles.empty());
  CHECK(cache.load(writeObj("junk.stl", "solid nothing\nthis is not a mesh\n"), Vec3::Ones(), problem) == nullptr);
  CHECK_FALSE(problem.empty());
}

TEST_CASE("the KUKA iiwa's meshes: every vertex within the hull", "[import][mesh]") {
  detail::MeshCache cache;
  std::string problem;
  const auto link = cache.load(fs::path(SSX_EXAMPLES_DIR) / "robots/kuka_iiwa/meshes/link_2.stl", Vec3::Ones(), problem);
  REQUIRE(link != nullptr);
  CHECK(link->hull_volume > 0.001);  // m^3: a link of an arm a metre long
  // every vertex inside the hull, or within 0.1 mm of it (btConvexHullComputer's integer grid)
  const auto& v = link->hull_vertices;
  const auto& t = link->hull_triangles;
  double outside = 0;
  for (const Vec3& p : link->vertices)
    for (std::size_t i = 0; i + 2 < t.size(); i += 3) {
      const Vec3 n = (v[t[i + 1]] - v[t[i]]).cross(v[t[i + 2]] - v[t[i]]).normalized();
      outside = std::max(outside, n.dot(p - v[t[i]]));
    }
  CHECK(outside < 1e-4);
}
