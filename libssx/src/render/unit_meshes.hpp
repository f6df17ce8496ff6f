#pragma once
// The unit meshes the osmesa engine draws every primitive from: a cube, spheres and cylinders of a
// chosen detail, a disc and a plane, centred on the origin, with outward normals.
#include <ssx/physic_node.hpp>

#include <vector>

namespace ssx::detail {

struct Vertex {
  float position[3];
  float normal[3];
};

/// The radius a regular polygon of `sides` needs to cover the area of the unit circle.
float equalAreaRadius(int sides);
/// A unit cube centred on the origin.
void boxMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx);
/// A unit-radius sphere of `stacks` x `slices` (its polygons as large as equalAreaRadius makes them).
void sphereMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx, int stacks, int slices);
/// A unit-radius cylinder of unit length along z, with caps.
void cylinderMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx, int slices);
/// A unit disc in the x-y plane, facing +z.
void discMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx, int slices);
/// A unit square in the x-y plane, facing +z.
void planeMesh(std::vector<Vertex>& v, std::vector<unsigned>& idx);
/// A scene's mesh, flat-shaded: each triangle its three corners with the face's normal
/// (degenerate triangles left out).
void flatMesh(const TriangleMesh& mesh, std::vector<Vertex>& v, std::vector<unsigned>& idx);

}  // namespace ssx::detail
