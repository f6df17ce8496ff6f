// The grid broadphase against brute force: every overlapping pair exactly once, in an order that
// depends only on the boxes.
#include "engines/grid_broadphase.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <set>
#include <utility>
#include <vector>

using ssx::Vec3;
using ssx::detail::GridBroadphase;

namespace {

// small boxes on a grid (many share an x), some scattered, a few large ones; owners shared by a
// few boxes each, some static (-1)
std::vector<GridBroadphase::Box> boxes(std::uint32_t seed, double jitter) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<GridBroadphase::Box> out;
  for (int i = 0; i < 600; ++i) {
    Vec3 c(0.3 * (i % 10), 0.3 * ((i / 10) % 10), 0.3 * (i / 100));
    c += jitter * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    const Vec3 half = Vec3(0.05 + 0.15 * u(rng), 0.05 + 0.15 * u(rng), 0.05 + 0.15 * u(rng));
    const int owner = u(rng) < 0.1 ? -1 : i / 3;
    out.push_back({c - half, c + half, owner});
  }
  for (int i = 0; i < 5; ++i) {  // large: a wall, a slab
    const Vec3 c(3 * u(rng), 3 * u(rng), 2 * u(rng));
    const Vec3 half(0.1 + 2 * u(rng), 0.1 + 2 * u(rng), 0.1 + u(rng));
    out.push_back({c - half, c + half, i % 2 == 0 ? -1 : 1000 + i});
  }
  return out;
}

std::vector<std::pair<int, int>> allPairs(GridBroadphase& grid, const std::vector<GridBroadphase::Box>& b) {
  grid.build(b, 0.6);
  std::vector<std::pair<int, int>> out;
  for (std::size_t c = 0; c < grid.chunkCount(); ++c) grid.pairs(c, out);
  return out;
}

}  // namespace

TEST_CASE("the grid broadphase finds every overlapping pair once, as brute force does", "[physics]") {
  for (double jitter : {0.0, 0.2, 1.0}) {
    INFO("jitter " << jitter);
    const auto b = boxes(7, jitter);
    GridBroadphase grid;
    const auto found = allPairs(grid, b);
    std::set<std::pair<int, int>> unique;
    for (auto [i, j] : found) unique.insert({std::min(i, j), std::max(i, j)});
    CHECK(unique.size() == found.size());  // none twice
    std::set<std::pair<int, int>> expected;
    for (int i = 0; i < static_cast<int>(b.size()); ++i)
      for (int j = i + 1; j < static_cast<int>(b.size()); ++j) {
        const auto &p = b[static_cast<std::size_t>(i)], &q = b[static_cast<std::size_t>(j)];
        const bool pairable = p.owner != q.owner && (p.owner >= 0 || q.owner >= 0);
        const bool overlap = (p.min.array() <= q.max.array()).all() && (q.min.array() <= p.max.array()).all();
        if (pairable && overlap) expected.insert({i, j});
      }
    REQUIRE(!expected.empty());
    CHECK(unique == expected);
  }
}

TEST_CASE("the grid broadphase's pair order depends only on the boxes, not on earlier builds", "[physics]") {
  const auto target = boxes(11, 0.2);
  GridBroadphase fresh;
  const auto once = allPairs(fresh, target);
  // the same boxes after other layouts (the sort starts from the last build's order)
  GridBroadphase used;
  (void)allPairs(used, boxes(12, 1.0));
  (void)allPairs(used, boxes(13, 0.0));
  CHECK(allPairs(used, target) == once);
}
