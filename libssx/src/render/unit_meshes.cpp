#include "render/unit_meshes.hpp"

#include <array>
#include <cmath>
#include <numbers>

namespace ssx::detail {

namespace {

void addQuad(std::vector<Vertex>& v, std::vector<unsigned>& idx, const std::array<float, 3>& n,
             const std::array<std::array<float, 3>, 4>& corners) {
  const auto base = static_cast<unsigned>(v.size());
  for (const auto& c : corners) v.push_back({{c[0], c[1], c[2]}, {n[0], n[1], n[2]}});
  for (unsigned k : {0u, 1u, 2u, 0u, 2u, 3u}) idx.push_back(base + k);
}

}  // namespace

// a unit cube centred on the origin
void boxMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx) {
  const float h = 0.5f;
  addQuad(v, idx, {1, 0, 0}, {{{h, -h, -h}, {h, h, -h}, {h, h, h}, {h, -h, h}}});
  addQuad(v, idx, {-1, 0, 0}, {{{-h, h, -h}, {-h, -h, -h}, {-h, -h, h}, {-h, h, h}}});
  addQuad(v, idx, {0, 1, 0}, {{{h, h, -h}, {-h, h, -h}, {-h, h, h}, {h, h, h}}});
  addQuad(v, idx, {0, -1, 0}, {{{-h, -h, -h}, {h, -h, -h}, {h, -h, h}, {-h, -h, h}}});
  addQuad(v, idx, {0, 0, 1}, {{{-h, -h, h}, {h, -h, h}, {h, h, h}, {-h, h, h}}});
  addQuad(v, idx, {0, 0, -1}, {{{-h, h, -h}, {h, h, -h}, {h, -h, -h}, {-h, -h, -h}}});
}

// the radius of a regular polygon of `sides` with the area of the unit circle: a coarse disc or
// cylinder looks as large as the round one it stands for
float equalAreaRadius(int sides) {
  const double pi = std::numbers::pi;
  return static_cast<float>(std::sqrt(2 * pi / (sides * std::sin(2 * pi / sides))));
}

// a unit sphere (radius 1; a coarse one a little larger, so that its outline has the circle's area)
void sphereMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx, int stacks, int slices) {
  const float pi = std::numbers::pi_v<float>, r = equalAreaRadius(slices);
  for (int i = 0; i <= stacks; ++i) {
    const float theta = pi * static_cast<float>(i) / stacks;
    for (int j = 0; j <= slices; ++j) {
      const float phi = 2 * pi * static_cast<float>(j) / slices;
      const float x = std::sin(theta) * std::cos(phi), y = std::sin(theta) * std::sin(phi), z = std::cos(theta);
      v.push_back({{r * x, r * y, r * z}, {x, y, z}});
    }
  }
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const auto a = static_cast<unsigned>(i * (slices + 1) + j), b = a + slices + 1;
      for (unsigned k : {a, b, a + 1, a + 1, b, b + 1}) idx.push_back(k);
    }
}

// a cylinder of radius 1 (a prism of equal cross-section) and length 1 along z, centred, with caps
void cylinderMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx, int slices) {
  const float pi = std::numbers::pi_v<float>, r = equalAreaRadius(slices);
  const auto side = static_cast<unsigned>(v.size());
  for (int j = 0; j <= slices; ++j) {
    const float phi = 2 * pi * static_cast<float>(j) / slices, c = std::cos(phi), s = std::sin(phi);
    v.push_back({{r * c, r * s, -0.5f}, {c, s, 0}});
    v.push_back({{r * c, r * s, 0.5f}, {c, s, 0}});
  }
  for (int j = 0; j < slices; ++j) {
    const auto a = side + static_cast<unsigned>(2 * j);
    for (unsigned k : {a, a + 2, a + 1, a + 1, a + 2, a + 3}) idx.push_back(k);
  }
  for (float z : {-0.5f, 0.5f}) {
    const auto centre = static_cast<unsigned>(v.size());
    v.push_back({{0, 0, z}, {0, 0, z > 0 ? 1.0f : -1.0f}});
    for (int j = 0; j <= slices; ++j) {
      const float phi = 2 * pi * static_cast<float>(j) / slices;
      v.push_back({{r * std::cos(phi), r * std::sin(phi), z}, {0, 0, z > 0 ? 1.0f : -1.0f}});
    }
    for (int j = 0; j < slices; ++j) {
      const auto a = centre + 1 + static_cast<unsigned>(j);
      if (z > 0)
        for (unsigned k : {centre, a, a + 1}) idx.push_back(k);
      else
        for (unsigned k : {centre, a + 1, a}) idx.push_back(k);
    }
  }
}

// a disc of radius 1 (a polygon of equal area) in the xy plane, facing +z
void discMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx, int slices) {
  const float pi = std::numbers::pi_v<float>, r = equalAreaRadius(slices);
  for (int j = 0; j < slices; ++j) {
    const float phi = 2 * pi * static_cast<float>(j) / slices;
    v.push_back({{r * std::cos(phi), r * std::sin(phi), 0}, {0, 0, 1}});
  }
  for (int j = 1; j + 1 < slices; ++j)
    for (unsigned k : {0u, static_cast<unsigned>(j), static_cast<unsigned>(j + 1)}) idx.push_back(k);
}

// a unit square in the xy plane, facing +z
void planeMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx) {
  addQuad(v, idx, {0, 0, 1}, {{{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}}});
}

void flatMesh(const TriangleMesh& mesh, std::vector<Vertex>& v, std::vector<unsigned>& idx) {
  for (std::size_t i = 0; i + 2 < mesh.triangles.size(); i += 3) {
    const Vec3 &a = mesh.vertices[mesh.triangles[i]], &b = mesh.vertices[mesh.triangles[i + 1]],
               &c = mesh.vertices[mesh.triangles[i + 2]];
    const Vec3 n = (b - a).cross(c - a);
    if (!(n.squaredNorm() > 0)) continue;  // (a degenerate triangle has no face)
    const Vec3 u = n.normalized();
    for (const Vec3* p : {&a, &b, &c}) {
      idx.push_back(static_cast<unsigned>(v.size()));
      v.push_back({{static_cast<float>(p->x()), static_cast<float>(p->y()), static_cast<float>(p->z())},
                   {static_cast<float>(u.x()), static_cast<float>(u.y()), static_cast<float>(u.z())}});
    }
  }
}

}  // namespace ssx::detail
