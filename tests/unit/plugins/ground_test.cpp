// ground: the floor's colour under a robot's points, from the floor colour and the regions painted
// over it (later over earlier); grey levels with noise kept within [0, 1]; what is wrong with the
// regions or points is said before anything runs.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace ssx;
using namespace ssx::test;
using Catch::Contains;

namespace {

Scene scene(const std::string& ground, const std::string& where = "0 0 0") {
  const std::string xml = R"(<scene><environment timestep="0.01"/>
    <type name="epuck" file=")" + (kArtifacts / "epuck.xml").string() + R"("/>
    <ground/>
    <artifact name="r" type="epuck" xyz=")" + where + R"(">)" + ground + R"(</artifact></scene>)";
  return loadSceneFromString(xml, "ground.xml", kArtifacts, testOptions());
}

const GroundMeasurement& reading(Environment& env) {
  const Artifact& a = *env.findArtifact("r");
  for (std::size_t i = 0; i < a.sensorCount(); ++i)
    if (const auto* m = dynamic_cast<const GroundMeasurement*>(&a.sensor(i).latest())) return *m;
  throw std::runtime_error("no ground sensor");
}

}  // namespace

TEST_CASE("ground: each point reads the colour painted last under it, or the floor's", "[ground]") {
  // a red disc, a black rectangle over part of it; points ahead of and behind the robot (facing +x)
  Scene s = scene(R"(<sensor index="2" points="0.03 0; -0.03 0; 0 0.5" floor="1 1 1"
                       regions="circle 0.1 0 0.1 1 0 0; rect -0.2 -0.2 0.02 0.2 0 0 0"/>)");
  Environment& env = *s.environment;
  env.step();
  const GroundMeasurement& m = reading(env);
  REQUIRE(m.readings.size() == 3);
  CHECK(m.colors[0] == Vec3(1, 0, 0));  // at x 0.03: in the disc, not the rectangle
  CHECK(m.readings[0] == Approx(0.299));
  CHECK(m.colors[1] == Vec3(0, 0, 0));  // at x -0.03: the rectangle, painted over the disc
  CHECK(m.readings[1] == 0.0);
  CHECK(m.colors[2] == Vec3(1, 1, 1));  // at y 0.5: the floor
  CHECK(m.readings[2] == Approx(1.0));
}

TEST_CASE("ground: the points move with the robot; noise stays within [0, 1]", "[ground]") {
  Scene s = scene(R"(<sensor index="2" points="0.03 0" regions="rect 0.5 -1 2 1 0.5 0.5 0.5" noise="0.2"/>)",
                  "0.48 0 0");
  Environment& env = *s.environment;
  double sum = 0, lo = 1, hi = 0;
  for (int i = 0; i < 1000; ++i) {
    env.step();
    const double r = reading(env).readings[0];  // its front point at x 0.51: grey 0.5
    sum += r;
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  CHECK(sum / 1000 == Approx(0.5).margin(0.02));
  CHECK(lo >= 0.0);
  CHECK(hi <= 1.0);
  CHECK(hi - lo > 0.8);
}

TEST_CASE("ground: regions and points that are not right are refused at their parameter", "[ground]") {
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" regions="square 0 0 1 1 1 1"/>)"), Contains("a region is 'circle"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" regions="circle 0 0 1 1 1"/>)"), Contains("needs 6 numbers"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" regions="circle 0 0 1 2 0 0"/>)"), Contains("colours are within 0..1"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" points="0.1"/>)"), Contains("a point is 'X Y'"));
}
