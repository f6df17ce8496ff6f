// proximity: an e-puck's eight infrared rays, cast with each engine's ray queries, read ARGoS's
// response exp(-d) at the distance geometry gives to a wall and to another robot, 0 where nothing is
// within range, never the robot itself; the linear response; uniform noise within its bounds.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

using namespace ssx;
using namespace ssx::test;
using Catch::Contains;

namespace {

constexpr double kDeg = std::numbers::pi / 180;
const double kAngles[] = {-17, -46, -90, -151, 151, 90, 46, 17};

// where a ray from the robot at the origin (facing +x) at `deg` meets a vertical circle, or +inf
double toCircle(double deg, const Vec3& centre, double radius) {
  const Vec3 u(std::cos(deg * kDeg), std::sin(deg * kDeg), 0);
  const Vec3 p = 0.036 * u - Vec3(centre.x(), centre.y(), 0);
  const double b = p.dot(u), c = p.squaredNorm() - radius * radius, disc = b * b - c;
  if (disc < 0) return INFINITY;
  const double t = -b - std::sqrt(disc);
  return t >= 0 ? t : INFINITY;
}

Scene scene(const std::string& engine, const std::string& sensor_override = "") {
  const std::string xml = R"(<scene><environment timestep="0.002"/><physics engine=")" + engine + R"("/>
    <type name="epuck" file=")" + (kArtifacts / "epuck.xml").string() + R"("/>
    <ground/>
    <obstacle name="wall" xyz="0.08 0 0.05"><box size="0.02 1 0.1"/></obstacle>
    <artifact name="me" type="epuck" xyz="0 0 0">)" + sensor_override + R"(</artifact>
    <artifact name="other" type="epuck" xyz="-0.09 0.02 0"/></scene>)";
  return loadSceneFromString(xml, "proximity.xml", kArtifacts, testOptions());
}

const ProximityMeasurement& reading(Environment& env, const std::string& name) {
  return dynamic_cast<const ProximityMeasurement&>(env.findArtifact(name)->sensor(0).latest());
}

}  // namespace

TEST_CASE("proximity: an e-puck's rays read exp(-d) at a wall and at another robot, 0 beyond range", "[proximity]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  Scene s = scene(engine);
  Environment& env = *s.environment;
  env.step(2);
  const ProximityMeasurement& m = reading(env, "me");
  REQUIRE(m.readings.size() == 8);
  for (int k = 0; k < 8; ++k) {
    const double a = kAngles[k];
    // the wall's face at x = 0.07; the other robot's body, a circle of 0.035 m at (-0.09, 0.02)
    const double wall = std::cos(a * kDeg) > 0 ? 0.07 / std::cos(a * kDeg) - 0.036 : INFINITY;
    const double robot = toCircle(a, Vec3(-0.09, 0.02, 0), 0.035);
    const double d = std::min(wall, robot);
    INFO("ray " << k << " at " << a << " deg: expected " << d << " m, got " << m.distances[k]);
    if (d <= 0.05) {
      CHECK(m.distances[k] == Approx(d).margin(1e-4));
      CHECK(m.readings[k] == Approx(std::exp(-d)).margin(1e-4));
    } else {
      CHECK(std::isinf(m.distances[k]));
      CHECK(m.readings[k] == 0.0);
    }
  }
  // the front pair sees the wall, a rear ray the other robot, the sides nothing
  CHECK(m.readings[0] > 0);
  CHECK(m.readings[7] > 0);
  CHECK((m.readings[3] > 0 || m.readings[4] > 0));
  CHECK(m.readings[2] == 0.0);
  CHECK(m.readings[5] == 0.0);
}

TEST_CASE("proximity: a linear response, and uniform noise kept within [0, 1]", "[proximity]") {
  Scene s = scene("ode", R"(<sensor plugin="proximity" angles="-17 90" range="0.05" radius="0.036" height="0.03"
                                response="linear" noise="0.1"/>)");
  Environment& env = *s.environment;
  double sum = 0, lo = 1, hi = 0, side_max = 0;
  const int n = 2000;
  const double d = 0.07 / std::cos(17 * kDeg) - 0.036;
  for (int i = 0; i < n; ++i) {
    env.step();
    const ProximityMeasurement& m = dynamic_cast<const ProximityMeasurement&>(env.findArtifact("me")->sensor(0).latest());
    sum += m.readings[0];
    lo = std::min(lo, m.readings[0]);
    hi = std::max(hi, m.readings[0]);
    side_max = std::max(side_max, m.readings[1]);
  }
  const double expected = 1 - d / 0.05;
  CHECK(sum / n == Approx(expected).margin(0.005));
  CHECK(lo >= expected - 0.1 - 1e-12);
  CHECK(hi <= expected + 0.1 + 1e-12);
  CHECK(hi - lo > 0.19);           // the noise spans its range
  CHECK(side_max <= 0.1 + 1e-12);  // nothing there: 0 plus noise, never below 0
  CHECK_THROWS_WITH(scene("ode", R"(<sensor plugin="proximity" angles="0 x"/>)"),
                    Contains("angles must be numbers in degrees"));
}

TEST_CASE("proximity: without angles, count rays are spread evenly from straight ahead", "[proximity]") {
  std::filesystem::create_directories("proximity_count");
  std::ofstream("proximity_count/puck.xml") << R"(<artifact>
  <physic name="body" mass="0.1"><cylinder radius="0.03" length="0.04" xyz="0 0 0.02"/></physic>
  <sensor plugin="proximity" count="4" range="0.2" height="0.02"/>
</artifact>
)";
  Scene s = loadSceneFromString(R"(<scene><physics gravity="0 0 0"/><type name="p" file="puck.xml"/>
    <obstacle name="wall" xyz="0 0.15 0.05"><box size="1 0.02 0.1"/></obstacle>
    <artifact name="me" type="p"/></scene>)",
                                "count.xml", std::filesystem::current_path() / "proximity_count", testOptions());
  Environment& env = *s.environment;
  env.step();
  const ProximityMeasurement& m = reading(env, "me");
  REQUIRE(m.angles.size() == 4);
  CHECK(m.angles[1] == Approx(M_PI / 2));
  // only the ray to the left (+y) meets the wall, 0.14 m out from the node's axis
  CHECK(std::isinf(m.distances[0]));
  CHECK(m.distances[1] == Approx(0.14).margin(1e-6));
  CHECK(std::isinf(m.distances[2]));
  CHECK(std::isinf(m.distances[3]));
}

TEST_CASE("proximity: a robot pressed against a wall reads it as touching, though its sensors sit inside the wall",
          "[proximity]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  // pressed into the wall: the front rays (0.036 m out, 17 deg off ahead) would start behind its face
  Scene s = scene(engine);
  Environment& env = *s.environment;
  env.start();
  Artifact& me = *env.findArtifact("me");
  BodyState pressed = env.bodyState(me.root().bodyIndex());
  pressed.pose.position.x() += 0.037;  // 2 mm into the wall: a step of contact leaves it most of that
  env.setBodyState(me.root().bodyIndex(), pressed);
  env.step();
  const ProximityMeasurement& m = reading(env, "me");
  CHECK(m.distances[0] == 0.0);  // ps0 and ps7, 17 deg either side of ahead
  CHECK(m.distances[7] == 0.0);
  CHECK(m.readings[0] == 1.0);
  CHECK(m.readings[7] == 1.0);
}
