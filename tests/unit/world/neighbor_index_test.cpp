// The environment's neighbour index: enabled on request, following the robots as they move.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <utility>
#include <vector>

using namespace ssx;

TEST_CASE("neighbour queries need to be enabled and follow the robots", "[range]") {
  Environment env;
  PhysicNodeSpec body;
  body.name = "body";
  body.mass = 1;
  body.shapes.push_back(Shape::sphere(0.1));
  env.addArtifact("a", {Vec3(0, 0, 10), Quat::Identity()}).addPhysicRoot(body);
  env.addArtifact("b", {Vec3(1, 0, 10), Quat::Identity()}).addPhysicRoot(body);
  env.start();
  std::vector<std::size_t> out;
  CHECK_THROWS_WITH(env.neighbors(Vec3::Zero(), 1.0, out), Catch::Contains("enableNeighborQueries"));
  env.enableNeighborQueries(1.0);
  env.neighbors(Vec3(0, 0, 10), 1.5, out);
  CHECK(out == std::vector<std::size_t>{0, 1});
  env.step(1000);  // both fall 4.9 m in 1 s: the index moves with them
  out.clear();
  env.neighbors(Vec3(0, 0, 10), 0.3, out);
  CHECK(out.empty());
  out.clear();
  env.neighbors(env.findArtifact("a")->pose().position, 0.3, out);
  CHECK(out == std::vector<std::size_t>{0});
  // the visitor form: the same artifacts, at their indexed positions
  std::vector<std::pair<std::size_t, Vec3>> seen;
  env.forEachNeighbor(env.findArtifact("b")->pose().position, 1.5,
                      [&seen](std::size_t id, const Vec3& p) { seen.emplace_back(id, p); });
  std::sort(seen.begin(), seen.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  REQUIRE(seen.size() == 2);
  CHECK(seen[0].first == 0);
  CHECK(seen[1].first == 1);
  CHECK(seen[1].second == env.findArtifact("b")->pose().position);
  CHECK_THROWS_WITH(Environment().forEachNeighbor(Vec3::Zero(), 1.0, [](std::size_t, const Vec3&) {}),
                    Catch::Contains("enableNeighborQueries"));
}
