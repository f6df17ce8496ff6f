// Attribute overrides (sweeps): applied before loading, problems reported where they were given.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("attribute overrides set scene attributes before loading and report problems where they were given",
          "[scene]") {
  const std::string xml = R"(<scene>
    <environment timestep="0.002" seed="1"/>
    <type name="q" file="mk_quad_formation.xml"/>
    <swarm type="q" count="2" name="a{i}" spacing="2"><driver formation_size="2"/></swarm>
    <swarm type="q" count="2" name="b{i}" spacing="2" xyz="0 5 0"><driver formation_size="2"/></swarm>
    <extension name="log" plugin="csv_logger" file="never_written.csv"/>
  </scene>)";
  const SourceLocation at{"sweep.xml", 7};
  SceneOptions options;
  options.overrides = {{"environment@timestep", "0.001", at},
                       {"swarm[name=b{i}]/driver@formation_gain", "3.5", at},
                       {"swarm[1]/sensor[index=2]@range", "1.5", at}};
  options.extensions = false;
  Scene scene = loadSceneFromString(xml, "m.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts", options);
  CHECK(scene.environment->timestep() == 1'000'000);
  CHECK(scene.environment->findArtifact("b1")->driverParameters().get<double>("formation_gain") == 3.5);
  CHECK(scene.environment->findArtifact("a1")->driverParameters().get<double>("formation_gain") != 3.5);
  CHECK(scene.environment->findArtifact("a0")->sensorParameters(2).get<double>("range") == 1.5);
  CHECK(scene.environment->extension("log") == nullptr);

  auto problems = [&](std::vector<AttributeOverride> overrides) {
    SceneOptions o;
    o.overrides = std::move(overrides);
    try {
      (void)loadSceneFromString(xml, "m.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts", o);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("loaded");
  };
  CHECK_THAT(problems({{"swarm/driver@formation_gain", "1", at}}),
             Contains("sweep.xml:7: error: target 'swarm/driver@formation_gain': 'swarm' matches 2 elements in "
                      "<scene>; pick one with swarm[k] or swarm[name=...]"));
  CHECK_THAT(problems({{"swarm[3]@count", "1", at}}), Contains("sweep.xml:7: error: target 'swarm[3]@count': no element"));
  CHECK_THAT(problems({{"environment", "1", at}}), Contains("is not a path like"));
  // the value is checked as the plugin declares it, and the error points at the override
  CHECK_THAT(problems({{"swarm[2]/driver@formation_gain", "-1", at}}),
             Contains("sweep.xml:7: error: <driver>: driver 'quadrotor': parameter 'formation_gain' must be"));
  CHECK_THAT(problems({{"environment@timestep", "-1", at}}),
             Contains("sweep.xml:7: error: <environment>: attribute 'timestep' must be positive"));
}
