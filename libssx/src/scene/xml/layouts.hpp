#pragma once
// Where the members of a <swarm> go, in the layout's own frame: pure functions of their arguments
// (the random layout of its stream), so the loader only reads attributes and reports.

#include <ssx/random.hpp>
#include <ssx/types.hpp>

#include <cstdint>
#include <vector>

namespace ssx::detail {

/// Rows of `columns` along x, `rows` of them along y, then layers along z, `spacing` apart.
std::vector<Vec3> gridLayout(std::int64_t count, double spacing, std::int64_t columns, std::int64_t rows);

/// Uniform in the box [lo, hi], members at least `min_distance` apart (rejection sampling, at
/// most 1000 tries per member). Returns fewer than `count` points when they do not fit.
std::vector<Vec3> randomLayout(std::int64_t count, const Vec3& lo, const Vec3& hi, double min_distance, Random& rng);

/// A Fibonacci sphere of `radius`: z_i = 1 - 2 (i + 0.5) / N, theta_i = i pi (3 - sqrt 5).
std::vector<Vec3> sphereLayout(std::int64_t count, double radius);

}  // namespace ssx::detail
