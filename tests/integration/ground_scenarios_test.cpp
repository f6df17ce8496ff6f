// Ground-robot scenarios (examples/ground): each scene runs to its end and does what it is for.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <iterator>
#include <set>

using namespace ssx;
using namespace ssx::test;

namespace {

const std::filesystem::path kGround = std::filesystem::path(SSX_EXAMPLES_DIR) / "ground";

Scene groundExample(const std::string& file) {
  SceneOptions options = testOptions();
  return loadScene(kGround / file, options);
}

}  // namespace

TEST_CASE("ground scenarios: diffusion: 1,000 e-pucks spread from a packed square over the arena in 60 s",
          "[scenario][diffusion]") {
  Scene scene = groundExample("diffusion.xml");
  Environment& env = *scene.environment;
  // the arena's 0.25 m cells (40 x 40) that have had an e-puck in them, and how many hold one now
  constexpr double kCell = 0.25;
  std::set<std::pair<int, int>> visited;
  auto occupied = [&] {
    std::set<std::pair<int, int>> now;
    for (std::size_t i = 0; i < env.artifactCount(); ++i) {
      const Artifact& a = std::as_const(env).artifact(i);
      if (a.rootCount() == 0 || a.root().isStatic()) continue;
      const Vec3 p = a.root().pose().position;
      now.insert({static_cast<int>(std::floor((p.x() + 5) / kCell)), static_cast<int>(std::floor((p.y() + 5) / kCell))});
    }
    visited.insert(now.begin(), now.end());
    return now.size();
  };
  // how far they are from their centroid, root mean square (packed: 2.5 m; spread evenly over the
  // arena: 4.1 m)
  auto dispersion = [&] {
    std::vector<Vec3> p;
    Vec3 c = Vec3::Zero();
    for (std::size_t i = 0; i < env.artifactCount(); ++i) {
      const Artifact& a = std::as_const(env).artifact(i);
      if (a.rootCount() == 0 || a.root().isStatic()) continue;
      p.push_back(a.root().pose().position);
      c += p.back();
    }
    c /= static_cast<double>(p.size());
    double sum = 0;
    for (const Vec3& q : p) sum += (q - c).head<2>().squaredNorm();
    return std::sqrt(sum / static_cast<double>(p.size()));
  };
  const double packed = dispersion();
  const double start = static_cast<double>(occupied()) / 1600;
  for (int s = 0; s < 60; ++s) {
    env.step(50);
    (void)occupied();
  }
  const double spread = static_cast<double>(occupied()) / 1600;
  const double spread_rms = dispersion();
  const double coverage = static_cast<double>(visited.size()) / 1600;
  INFO("cells held at the start " << start * 100 << " %, after 60 s " << spread * 100 << " %; visited " << coverage * 100
                                  << " %; rms distance from the centroid " << packed << " m, after 60 s " << spread_rms << " m");
  CHECK(start < 0.42);     // 25 x 25 of the 40 x 40 cells (and the rows the grid's edges straddle)
  CHECK(coverage > 0.95);  // nearly every cell of the arena was reached
  CHECK(spread_rms > packed + 0.8);  // and they spread out
  // every e-puck is inside the arena, upright, on the floor
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    const Artifact& a = std::as_const(env).artifact(i);
    if (a.rootCount() == 0 || a.root().isStatic()) continue;
    const Pose p = a.root().pose();
    CHECK((std::abs(p.position.x()) < 5 && std::abs(p.position.y()) < 5));
    CHECK(std::abs(p.position.z()) < 0.002);
  }
}

TEST_CASE("ground scenarios: aggregation: BEECLUST gathers 60 e-pucks on the dark spot in 3 minutes; robots that "
          "never wait do not gather", "[scenario][aggregation]") {
  // the scene as written, and the same robots told never to wait (a control run)
  std::ifstream file(kGround / "aggregation.xml");
  const std::string xml((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  REQUIRE(xml.find(R"(wait_max="60")") != std::string::npos);
  auto onSpot = [&](const std::string& text) {
    Scene scene = loadSceneFromString(text, "aggregation.xml", kGround, testOptions());
    Environment& env = *scene.environment;
    env.step(9000);  // 180 s
    int on = 0, all = 0;
    for (std::size_t i = 0; i < env.artifactCount(); ++i) {
      const Artifact& a = std::as_const(env).artifact(i);
      if (a.driver() == nullptr) continue;
      ++all;
      const Vec3 p = a.root().pose().position;
      if (std::hypot(p.x() - 0.7, p.y() - 0.7) < 0.45 + 0.035) ++on;
    }
    return static_cast<double>(on) / all;
  };
  const double gathered = onSpot(xml);
  std::string never = xml;
  never.replace(never.find(R"(wait_max="60")"), 13, R"(wait_max="0" )");
  const double control = onSpot(never);
  INFO("on the dark spot after 180 s: " << gathered * 100 << " %; never waiting: " << control * 100
                                        << " % (the spot is 7 % of the arena)");
  CHECK(gathered > 0.4);
  CHECK(control < 0.2);
}
