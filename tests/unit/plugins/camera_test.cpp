// The camera sensor: images and depth of what is in front of it, following its artifact, and a
// clear error without a drawing engine.
// Headless (OSMesa); every test name contains "render".
#include <ssx/ssx.hpp>

#include "render_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

using namespace ssx;
using namespace ssx::test;
namespace fs = std::filesystem;

TEST_CASE("render: a camera sensor without a drawing engine fails at start and says what to do", "[render]") {
  Scene s = loadRenderScene(R"(<type name="post" file="camera_post.xml"/><artifact name="eye" type="post"/>)");
  CHECK_THROWS_WITH(s.environment->start(), Catch::Contains("engine=\"osmesa\""));
}

TEST_CASE("render: a red box in front of the camera fills the centre, at its known depth", "[render]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  Scene s = loadRenderScene(R"(<render engine="osmesa" background="0.2 0.4 0.6"/>
    <type name="post" file="camera_post.xml"/>
    <artifact name="eye" type="post" xyz="0 0 1"/>
    <obstacle name="box" xyz="5 0 1" color="1 0 0"><box size="1 1 1"/></obstacle>)");
  Environment& env = *s.environment;
  env.step();
  const CameraMeasurement& m = image(env);
  REQUIRE(m.image.width == 64);
  REQUIRE(m.image.height == 48);
  const std::uint8_t* c = m.image.pixel(32, 24);
  INFO("centre pixel " << int(c[0]) << " " << int(c[1]) << " " << int(c[2]));
  CHECK(c[0] > 150);
  CHECK(c[1] < 40);
  CHECK(c[2] < 40);
  // the box's near face is at x = 4.5, the camera at x = 0.2
  CHECK(m.image.depthAt(32, 24) == Approx(4.3).epsilon(0.01));
  // a corner pixel misses the box: background colour, depth infinite
  const std::uint8_t* corner = m.image.pixel(0, 0);
  CHECK(std::abs(corner[0] - 51) <= 1);
  CHECK(std::abs(corner[2] - 153) <= 1);
  CHECK(std::isinf(m.image.depthAt(0, 0)));
  CHECK(m.view.pose.position.isApprox(Vec3(0.2, 0, 1)));
}

TEST_CASE("render: a falling robot moves down in a fixed camera's image", "[render]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  Scene s = loadRenderScene(R"(<render engine="osmesa"/>
    <type name="post" file="camera_post.xml"/><type name="ball" file="yellow_ball.xml"/>
    <artifact name="eye" type="post" xyz="0 0 1"/>
    <artifact name="ball" type="ball" xyz="6 0 2"/>)");
  Environment& env = *s.environment;
  env.step();
  const double row_before = yellowRow(image(env).image);
  env.step(250);  // 0.5 s: 1.2 m lower
  const double row_after = yellowRow(image(env).image);
  INFO("rows " << row_before << " -> " << row_after);
  REQUIRE(row_before >= 0);
  REQUIRE(row_after >= 0);
  CHECK(row_before < 24);        // above the optical axis at first
  CHECK(row_after > row_before + 5);  // then lower in the picture (rows grow downwards)
}
