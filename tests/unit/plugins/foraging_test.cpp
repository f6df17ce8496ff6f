// foraging: an item lying in the nest that nobody holds counts as delivered and goes back, at rest,
// into the area; one held there does not count until let go; the count is saved with the state;
// what is wrong with the nest, the area or the items is said before anything runs.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

using namespace ssx;
using namespace ssx::test;
using Catch::Contains;

namespace {

// an e-puck (no controller) beside two items: one in the nest (a circle of 0.3 m at the origin),
// one outside it
Scene scene(const std::string& extension = R"(nest="0 0 0.3" area="2 -1 3 1")") {
  const std::string xml = R"(<scene><environment timestep="0.01" seed="2"/>
    <type name="epuck" file=")" + (kArtifacts / "epuck.xml").string() + R"("/>
    <type name="item" file=")" + (kArtifacts / "item.xml").string() + R"("/>
    <ground/>
    <artifact name="r" type="epuck" xyz="-0.1 0 0"/>
    <artifact name="item_in" type="item" xyz="0.1 0 0"/>
    <artifact name="item_out" type="item" xyz="1 0 0"/>
    <extension name="foraging" plugin="foraging" )" +
                          (extension.find("items=") == std::string::npos ? "items=\"item_\" " : "") + extension + R"(/></scene>)";
  return loadSceneFromString(xml, "foraging.xml", kArtifacts, testOptions());
}

double delivered(const Environment& env) {
  std::vector<Metric> m;
  dynamic_cast<const MetricSource&>(*env.extension("foraging")).metrics(m);
  return m.at(0).value;
}

}  // namespace

TEST_CASE("foraging: an item in the nest that nobody holds is delivered and put back in the area, a held one waits",
          "[foraging]") {
  Scene s = scene();
  Environment& env = *s.environment;
  env.start();
  PhysicNode& robot = env.findArtifact("r")->root();
  PhysicNode& in = env.findArtifact("item_in")->root();
  const PhysicNode& out = env.findArtifact("item_out")->root();
  robot.attach(in);  // held: not delivered
  env.step(10);
  CHECK(delivered(env) == 0);
  CHECK(in.pose().position.x() == Approx(0.1).margin(1e-3));
  robot.release();
  env.step();
  CHECK(delivered(env) == 1);
  const Vec3 p = in.pose().position;
  CHECK(p.x() >= 2);  // in the area
  CHECK(p.x() <= 3);
  CHECK(std::abs(p.y()) <= 1);
  CHECK(in.state().linear_velocity.norm() < 0.1);
  CHECK(out.pose().position.x() == Approx(1).margin(1e-3));  // outside the nest: left alone
  // the count is part of the saved state
  const auto saved = env.saveState();
  env.step(10);
  CHECK(delivered(env) == 1);
  Scene again = scene();
  again.environment->restoreState(saved);
  CHECK(delivered(*again.environment) == 1);
}

TEST_CASE("foraging: a nest, area or item list that does not make sense is refused before anything runs",
          "[foraging]") {
  CHECK_THROWS_WITH(scene(R"(nest="0 0 0" area="2 -1 3 1")"), Contains("radius must be positive"));
  CHECK_THROWS_WITH(scene(R"(nest="0 0 0.3" area="3 -1 2 1")"), Contains("X0 < X1"));
  CHECK_THROWS_WITH(scene(R"(nest="0 0 0.3" area="2 -1 3")"), Contains("X0 Y0 X1 Y1"));
  CHECK_THROWS_WITH(scene(R"(items="crate" nest="0 0 0.3" area="2 -1 3 1")"), Contains("starting with 'crate'"));
}
