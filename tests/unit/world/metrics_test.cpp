// Metrics: a plugin in another library publishes named values that anyone finds through
// ssx::MetricSource; the names are fixed once configured and the values come in their order.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace ssx;

TEST_CASE("metrics: a formation quadrotor publishes its formation error, a hovering one publishes nothing",
          "[metrics]") {
  Scene scene = loadSceneFromString(R"(<scene><environment timestep="0.002" seed="2"/>
    <type name="f" file="mk_quad_formation.xml"/><type name="h" file="mk_quad.xml"/><ground/>
    <swarm type="f" count="4" name="f{i}" spacing="1.5" columns="4" xyz="0 0 0.04"><driver formation_size="4" formation_radius="1"
      formation_center="0 0 1.5"/></swarm>
    <artifact name="solo" type="h" xyz="0 6 0.04"/></scene>)",
                                    "metrics.xml", test::kArtifacts);
  Environment& env = *scene.environment;
  env.start();
  const auto* member = dynamic_cast<const MetricSource*>(env.findArtifact("f0")->driver());
  const auto* solo = dynamic_cast<const MetricSource*>(env.findArtifact("solo")->driver());
  REQUIRE(member != nullptr);  // the cast works across the plugin library's boundary
  REQUIRE(solo != nullptr);
  CHECK(member->metricNames() == std::vector<std::string>{"formation_error"});
  CHECK(solo->metricNames().empty());
  std::vector<Metric> values;
  solo->metrics(values);
  CHECK(values.empty());
  // the members start 1.5 m apart on a line, resting on the ground, and end on a circle of radius
  // 1: once they have climbed (2 s), the error shrinks
  env.step(1000);
  member->metrics(values);
  REQUIRE(values.size() == 1);
  CHECK(values[0].name == "formation_error");
  const double early = values[0].value;
  env.step(6500);
  values.clear();
  member->metrics(values);
  REQUIRE(values.size() == 1);
  CHECK(std::isfinite(values[0].value));
  CHECK(values[0].value < early);
}
