// Swarm layouts: grid, Fibonacci sphere and seeded random placements.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("swarm layouts place artifacts on a grid, on a Fibonacci sphere and at seeded random", "[scene]") {
  Scene scene = loadScene(kData / "valid" / "layouts.xml", testOptions());
  Environment& env = *scene.environment;
  CHECK(env.artifactCount() == 70 + 12 + 50 + 1);
  // sphere: every robot 4 m from the centre; neighbours 1.48 to 1.65 m apart for N = 70
  double nearest_min = 1e9, nearest_max = 0;
  for (int i = 0; i < 70; ++i) {
    const Vec3 p = env.findArtifact("s" + std::to_string(i))->pose().position;
    CHECK((p - Vec3(0, 0, 5)).norm() == Approx(4.0).epsilon(1e-9));
    double nearest = 1e9;
    for (int j = 0; j < 70; ++j)
      if (j != i) nearest = std::min(nearest, (p - env.findArtifact("s" + std::to_string(j))->pose().position).norm());
    nearest_min = std::min(nearest_min, nearest);
    nearest_max = std::max(nearest_max, nearest);
  }
  CHECK(nearest_min > 1.3);
  CHECK(nearest_max < 1.8);
  // grid: 4 columns along x, spacing 2
  CHECK(env.findArtifact("g5")->pose().position.isApprox(Vec3(12, 2, 0)));
  // random: inside the box, and the same for the same seed
  for (int i = 0; i < 50; ++i) {
    const Vec3 p = env.findArtifact("r" + std::to_string(i))->pose().position;
    CHECK(p.x() >= -20);
    CHECK(p.x() <= -10);
    CHECK(p.y() <= -15);
    CHECK(p.z() >= 1);
  }
  Scene again = loadScene(kData / "valid" / "layouts.xml", testOptions());
  CHECK(again.environment->findArtifact("r7")->pose().position == env.findArtifact("r7")->pose().position);
  SceneOptions other = testOptions();
  other.seed = 6;
  Scene reseeded = loadScene(kData / "valid" / "layouts.xml", other);
  CHECK(reseeded.environment->findArtifact("r7")->pose().position != env.findArtifact("r7")->pose().position);
  // the included fragment's obstacle
  CHECK(env.findArtifact("pillar") != nullptr);
  CHECK(env.findArtifact("pillar")->root().isStatic());
}
