// The environment effects: the wind alone, the scene's <wind> on every quadrotor, each robot's own turbulence (ground effect and downwash: quadrotor_model_test.cpp).
#include "effects.hpp"
#include "part_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace ssx;
using namespace ssx::quadrotor;
using namespace ssx::quadrotor::test;
namespace fs = std::filesystem;

TEST_CASE("the wind alone: the mean, and a gust that rises and falls as 1 - cos", "[quadrotor][parts]") {
  WindParams p;
  p.mean = Vec3(2, 0, 0);
  p.gust = Vec3(0, 3, 0);
  p.gust_start = 1;
  p.gust_duration = 2;
  Wind wind;
  wind.configure(p, 0.0);
  REQUIRE(wind.active());
  Random random(1);
  CHECK(wind.air(0.5, 0.01, Vec3(0, 0, 1), Vec3::Zero(), random) == Vec3(2, 0, 0));
  CHECK(wind.air(2.0, 0.01, Vec3(0, 0, 1), Vec3::Zero(), random).isApprox(Vec3(2, 3, 0), 1e-12));  // its peak
  CHECK(wind.air(1.5, 0.01, Vec3(0, 0, 1), Vec3::Zero(), random).isApprox(Vec3(2, 1.5, 0), 1e-12));
  CHECK(wind.air(3.5, 0.01, Vec3(0, 0, 1), Vec3::Zero(), random) == Vec3(2, 0, 0));
  Wind calm;
  calm.configure(WindParams{}, 0.0);
  CHECK_FALSE(calm.active());
}

TEST_CASE("the scene's wind pushes every quadrotor downwind, an artifact's own wind overrides it",
          "[quadrotor][parts]") {
  Scene s = sceneOf("<wind mean=\"4 0 0\"/>" + quad("a", "0 0 1") + quad("b", "0 3 1") +
                    quad("calm", "0 6 1", "wind=\"0 0 0\""));
  Environment& env = *s.environment;
  CHECK(env.settings().wind.mean == Vec3(4, 0, 0));
  env.step(250);  // 0.5 s: the position loop has not caught the drift yet
  const double a = env.findArtifact("a")->pose().position.x();
  const double b = env.findArtifact("b")->pose().position.x();
  const double calm = env.findArtifact("calm")->pose().position.x();
  INFO("downwind: a " << a << " m, b " << b << " m, calm " << calm << " m");
  CHECK(a > 0.005);
  CHECK(b == a);  // without turbulence the same wind moves them alike
  CHECK(std::abs(calm) < 1e-6);
}

TEST_CASE("the scene's turbulence is each robot's own, and the same again from the same seed", "[quadrotor][parts]") {
  const auto run = [](std::uint64_t seed) {
    Scene s = sceneOf("<wind turbulence_w20=\"7.7\"/>" + quad("a", "0 0 1") + quad("b", "0 3 1"), seed);
    s.environment->step(1000);
    const Vec3 a = s.environment->findArtifact("a")->pose().position;
    const Vec3 b = s.environment->findArtifact("b")->pose().position - Vec3(0, 3, 0);
    return std::pair(a, b);
  };
  const auto [a, b] = run(1);
  INFO("a moved " << (a - Vec3(0, 0, 1)).transpose() << ", b " << (b - Vec3(0, 0, 1)).transpose());
  CHECK((a - Vec3(0, 0, 1)).norm() > 1e-3);  // it felt turbulence
  CHECK((a - b).norm() > 1e-3);              // not the same as its neighbour's
  const auto [a2, b2] = run(1);
  CHECK(a2 == a);
  CHECK(b2 == b);
}
