// Whole scenes: the example flies and logs, and a scene with plugins is reproducible on any thread count.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("a scene with plugins runs bitwise identically on 1 and 2 threads", "[scene][determinism]") {
  auto hashAfter = [](int threads) {
    SceneOptions o = testOptions();
    o.threads = threads;
    Scene scene = loadScene(kData / "valid" / "layouts.xml", o);
    scene.environment->step(200);
    return scene.environment->stateHash();
  };
  CHECK(hashAfter(1) == hashAfter(2));
}

TEST_CASE("the example scene loads, flies and logs", "[scene]") {
  fs::remove("hover_swarm_poses.csv");
  Scene scene = loadScene(fs::path(SSX_EXAMPLES_DIR) / "scenes" / "hover_swarm.xml");
  CHECK(scene.warnings.empty());
  CHECK(scene.duration == toNanoseconds(10.0));
  Environment& env = *scene.environment;
  CHECK(env.artifactCount() == 25 + 4 + 2 + 1);
  env.step(2500);  // 5 s
  // every robot holds 1 m above where it started (pose noise 2 mm)
  for (int i = 0; i < 25; ++i)
    CHECK(env.findArtifact("robot" + std::to_string(i))->pose().position.z() == Approx(1.05).margin(0.02));
  env.stop();
  std::ifstream csv("hover_swarm_poses.csv");
  std::string header;
  std::getline(csv, header);
  CHECK(header == "time_s,artifact,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz");
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  CHECK(rows == 3 * 250);  // three robots at 50 Hz for 5 s
}
