#pragma once
// Which shapes of different owners overlap, and how deeply: the scene loader's check that no
// robot starts inside another, an obstacle or the ground. Engine-neutral; computed with ODE's
// collision library (ode/ode_overlaps.cpp), which every build of libssx has, whatever engine
// the scene steps with.

#include <ssx/physic_node.hpp>
#include <ssx/types.hpp>

#include <cstddef>
#include <span>
#include <vector>

namespace ssx::detail {

/// A shape where it is in the world, and who it belongs to.
struct PosedShape {
  const Shape* shape = nullptr;
  Pose world;              // the shape's frame in the world (its own pose included)
  std::size_t owner = 0;   // shapes of one owner never count as overlapping
  bool is_static = false;  // two static shapes never count either
};

/// Two owners whose shapes overlap: the deepest penetration between them, and where.
struct ShapeOverlap {
  std::size_t first = 0;  // index into the shapes given, the lower owner's
  std::size_t second = 0;
  double depth = 0.0;  // m
  Vec3 point = Vec3::Zero();
};

/// Every pair of owners with shapes overlapping by more than `min_depth` (m), one entry per pair
/// (its deepest contact), ordered by the first shape's, then the second shape's index.
std::vector<ShapeOverlap> findShapeOverlaps(std::span<const PosedShape> shapes, double min_depth);

}  // namespace ssx::detail
