#include <ssx/random.hpp>
#include <ssx/spatial_index.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>

using namespace ssx;

TEST_CASE("neighbour queries return exactly what a brute-force search returns", "[spatial]") {
  Random r(17);
  int dense = 0, sparse = 0;  // which column table each index chose
  for (double cell : {0.5, 2.0, 7.0}) {
    for (int n : {0, 1, 50, 3000}) {
      std::vector<Vec3> points;
      std::vector<std::size_t> ids;
      for (int i = 0; i < n; ++i) {
        // a cloud around the origin, with a dense clump and some duplicates
        Vec3 p(r.uniform(-30, 30), r.uniform(-30, 30), r.uniform(-5, 10));
        if (i % 7 == 0) p = Vec3(r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1));
        if (i % 13 == 0 && i > 0) p = points.back();
        points.push_back(p);
        ids.push_back(static_cast<std::size_t>(i) * 3 + 1);  // ids need not be positions
      }
      SpatialIndex index(cell);
      index.rebuild(points, ids);
      CHECK(index.size() == points.size());
      if (n > 0) ++(index.dense() ? dense : sparse);
      for (int q = 0; q < 200; ++q) {
        const Vec3 c(r.uniform(-35, 35), r.uniform(-35, 35), r.uniform(-8, 12));
        const double radius = q % 10 == 0 ? 0.0 : r.uniform(0.1, 12.0);
        std::vector<std::size_t> got{999999};  // the index appends
        index.query(c, radius, got);
        std::vector<std::size_t> expected{999999};
        for (std::size_t i = 0; i < points.size(); ++i)
          if ((points[i] - c).squaredNorm() <= radius * radius) expected.push_back(ids[i]);
        REQUIRE(got == expected);
        // the visitor sees the same points, each once, with their indexed positions
        std::vector<SpatialIndex::Hit> visited;
        index.forEach(
            c, radius,
            [](void* out, std::size_t id, const Vec3& p) { static_cast<std::vector<SpatialIndex::Hit>*>(out)->push_back({id, p}); },
            &visited);
        std::vector<SpatialIndex::Hit> hits;
        index.query(c, radius, hits);
        std::sort(visited.begin(), visited.end(), [](const auto& a, const auto& b) {
          return a.id != b.id ? a.id < b.id : std::lexicographical_compare(a.point.begin(), a.point.end(), b.point.begin(), b.point.end());
        });
        std::sort(hits.begin(), hits.end(), [](const auto& a, const auto& b) {
          return a.id != b.id ? a.id < b.id : std::lexicographical_compare(a.point.begin(), a.point.end(), b.point.begin(), b.point.end());
        });
        REQUIRE(visited.size() == hits.size());
        for (std::size_t k = 0; k < hits.size(); ++k) {
          REQUIRE(visited[k].id == hits[k].id);
          REQUIRE(visited[k].point == hits[k].point);
        }
      }
    }
  }
  // both tables were tried: a swarm's rectangle of columns is dense, a few far-apart points sparse
  CHECK(dense >= 3);
  CHECK(sparse >= 2);
}

TEST_CASE("the spatial index refuses a non-positive cell size", "[spatial]") {
  CHECK_THROWS(SpatialIndex(0.0));
  CHECK_THROWS(SpatialIndex(-1.0));
}

namespace {
// every point's visit order for a query around each point: what a caller that keeps the index's
// order (forEach) sees
std::vector<std::size_t> visitOrder(const SpatialIndex& index, const std::vector<Vec3>& points, double radius) {
  std::vector<std::size_t> order;
  for (const Vec3& c : points)
    index.forEach(
        c, radius,
        [](void* out, std::size_t id, const Vec3&) { static_cast<std::vector<std::size_t>*>(out)->push_back(id); },
        &order);
  return order;
}
}  // namespace

TEST_CASE("an index rebuilt from its last order visits exactly as one built afresh", "[spatial]") {
  // a rebuild with as many points as last time sorts the last order again (insertion, or a full
  // sort past its budget of moves): the order must be the one a new index makes, moves small or large
  Random r(5);
  std::vector<Vec3> points;
  std::vector<std::size_t> ids;
  for (int i = 0; i < 2000; ++i) {
    points.emplace_back(r.uniform(-20, 20), r.uniform(-20, 20), r.uniform(0, 4));
    ids.push_back(static_cast<std::size_t>(1999 - i) / 2);  // pairs of equal ids: ties in (cell, id)
  }
  SpatialIndex kept(1.0);
  kept.rebuild(points, ids);
  for (double step : {0.01, 0.2, 5.0, 40.0}) {  // a few points change cells .. nearly all (full sort)
    for (int round = 0; round < 3; ++round) {
      for (Vec3& p : points) p += Vec3(r.uniform(-step, step), r.uniform(-step, step), r.uniform(-step, step));
      kept.rebuild(points, ids);
      SpatialIndex fresh(1.0);
      fresh.rebuild(points, ids);
      REQUIRE(visitOrder(kept, points, 1.5) == visitOrder(fresh, points, 1.5));
    }
  }
  // and with another number of points (the last order does not apply)
  points.resize(1500);
  ids.resize(1500);
  kept.rebuild(points, ids);
  SpatialIndex fresh(1.0);
  fresh.rebuild(points, ids);
  CHECK(visitOrder(kept, points, 1.5) == visitOrder(fresh, points, 1.5));
  CHECK(kept.size() == 1500);
  // mismatched arguments are refused
  ids.pop_back();
  CHECK_THROWS_WITH(kept.rebuild(points, ids), Catch::Contains("as many ids as points"));
}
