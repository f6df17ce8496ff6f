// The unit meshes every primitive is drawn from: closed where they should be, wound so that their
// front faces point outward, and as large as the shapes they stand for (a coarse cylinder or disc
// covers the round one's area).
#include "render/unit_meshes.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

using namespace ssx::detail;

namespace {

struct Mesh {
  std::vector<Vertex> v;
  std::vector<unsigned> idx;
};

Eigen::Vector3d position(const Vertex& v) { return {v.position[0], v.position[1], v.position[2]}; }
Eigen::Vector3d normal(const Vertex& v) { return {v.normal[0], v.normal[1], v.normal[2]}; }

// the volume a closed, outward-wound mesh encloses (divergence theorem), and its facing checks
struct Facts {
  double volume = 0;
  double area = 0;
  int inward = 0;         // triangles whose winding disagrees with their vertices' normals
  int unit_normals = 0;   // vertices whose normal has length 1
  int open_edges = 0;     // edges (by position) used by one triangle only, counted per direction
};

Facts facts(const Mesh& m) {
  Facts f;
  // edges keyed by rounded positions: a closed mesh has every directed edge matched by its reverse
  auto key = [](const Eigen::Vector3d& p) {
    return std::array<long, 3>{std::lround(p.x() * 1e5), std::lround(p.y() * 1e5), std::lround(p.z() * 1e5)};
  };
  std::map<std::pair<std::array<long, 3>, std::array<long, 3>>, int> edges;
  REQUIRE(m.idx.size() % 3 == 0);
  for (std::size_t t = 0; t < m.idx.size(); t += 3) {
    const Vertex &a = m.v.at(m.idx[t]), &b = m.v.at(m.idx[t + 1]), &c = m.v.at(m.idx[t + 2]);
    const Eigen::Vector3d pa = position(a), pb = position(b), pc = position(c);
    const Eigen::Vector3d cross = (pb - pa).cross(pc - pa);
    f.volume += pa.dot(pb.cross(pc)) / 6;
    f.area += cross.norm() / 2;
    if (cross.dot(normal(a) + normal(b) + normal(c)) <= 0) ++f.inward;
    const Eigen::Vector3d p[3] = {pa, pb, pc};
    for (int k = 0; k < 3; ++k) ++edges[{key(p[k]), key(p[(k + 1) % 3])}];
  }
  for (const auto& [edge, count] : edges) {
    const auto reverse = edges.find({edge.second, edge.first});
    if (edge.first != edge.second && (reverse == edges.end() || reverse->second != count)) ++f.open_edges;
  }
  for (const Vertex& v : m.v) f.unit_normals += std::abs(normal(v).norm() - 1) < 1e-6 ? 1 : 0;
  return f;
}

}  // namespace

TEST_CASE("unit meshes: the cube is closed, outward and of volume 1", "[render][meshes]") {
  Mesh m;
  boxMesh(m.v, m.idx);
  const Facts f = facts(m);
  CHECK(m.idx.size() == 36);
  CHECK(f.volume == Approx(1.0).epsilon(1e-6));
  CHECK(f.area == Approx(6.0).epsilon(1e-6));
  CHECK(f.inward == 0);
  CHECK(f.open_edges == 0);
  CHECK(f.unit_normals == static_cast<int>(m.v.size()));
}

TEST_CASE("unit meshes: a coarse polygon of equalAreaRadius has the unit circle's area", "[render][meshes]") {
  for (int sides : {3, 6, 8, 16, 64}) {
    const double r = equalAreaRadius(sides);
    const double polygon = sides * r * r * std::sin(2 * std::numbers::pi / sides) / 2;
    INFO(sides);
    CHECK(polygon == Approx(std::numbers::pi).epsilon(1e-6));
    CHECK(r > 1.0);  // it reaches beyond the circle between its corners' gaps
  }
  Mesh disc;
  discMesh(disc.v, disc.idx, 8);
  const Facts f = facts(disc);
  CHECK(f.area == Approx(std::numbers::pi).epsilon(1e-6));
  CHECK(f.inward == 0);
}

TEST_CASE("unit meshes: cylinders are closed prisms of volume pi at every detail", "[render][meshes]") {
  for (int slices : {6, 12, 32}) {
    Mesh m;
    cylinderMesh(m.v, m.idx, slices);
    const Facts f = facts(m);
    INFO(slices);
    CHECK(f.volume == Approx(std::numbers::pi).epsilon(1e-5));
    CHECK(f.inward == 0);
    CHECK(f.open_edges == 0);
    CHECK(f.unit_normals == static_cast<int>(m.v.size()));
  }
}

TEST_CASE("unit meshes: spheres are closed and outward, approaching the unit ball as detail grows", "[render][meshes]") {
  double previous_error = 1e9;
  for (auto [stacks, slices] : {std::pair{6, 8}, std::pair{12, 16}, std::pair{24, 32}}) {
    Mesh m;
    sphereMesh(m.v, m.idx, stacks, slices);
    const Facts f = facts(m);
    INFO(stacks << " x " << slices);
    CHECK(f.inward <= 2 * slices);  // only the degenerate triangles at the poles may have no winding
    CHECK(f.open_edges == 0);
    CHECK(f.unit_normals == static_cast<int>(m.v.size()));
    const double error = std::abs(f.volume - 4.0 / 3.0 * std::numbers::pi);
    CHECK(error < previous_error);
    previous_error = error;
  }
  CHECK(previous_error < 0.05 * 4.0 / 3.0 * std::numbers::pi);
}
