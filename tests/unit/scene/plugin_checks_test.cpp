// The builder's plugin checks: what a placing element sets on its type's plugins, its period.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <filesystem>

using namespace ssx;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("a placing element's period overrides the type's plugin period and is no parameter", "[scene]") {
  const std::string xml = R"(<scene>
    <type name="q" file="mk_quad_formation.xml"/>
    <swarm type="q" count="2" name="q{i}" spacing="2"><sensor index="2" period="3"/><driver period="2"/></swarm>
    <artifact name="plain" type="q" xyz="0 5 0"/>
  </scene>)";
  Scene scene = loadSceneFromString(xml, "memory.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
  const Artifact& q = *scene.environment->findArtifact("q1");
  CHECK(q.sensor(2).periodSteps() == 3);  // the type says 10
  CHECK(q.sensor(0).periodSteps() == 1);
  CHECK(q.driver()->periodSteps() == 2);
  CHECK(scene.environment->findArtifact("plain")->sensor(2).periodSteps() == 10);
  for (const auto& w : scene.warnings) CHECK_THAT(w.message, !Catch::Contains("period"));
  std::vector<std::string> log;  // unread plugin parameters are reported at start
  scene.environment->setLogSink([&](LogLevel, std::string_view m) { log.emplace_back(m); });
  scene.environment->start();
  for (const auto& m : log) CHECK_THAT(m, !Catch::Contains("period"));
}

TEST_CASE("a period that is no count of steps is reported once, by the reader or by the builder", "[scene]") {
  const std::string xml = R"(<scene>
    <type name="q" file="mk_quad_formation.xml"/>
    <artifact name="q" type="q"><driver period="0"/></artifact>
  </scene>)";
  try {
    (void)loadSceneFromString(xml, "memory.xml", test::kArtifacts, testOptions());
    FAIL("loaded");
  } catch (const SceneError& e) {
    const std::string text = e.what();
    CHECK_THAT(text, Contains("memory.xml:3: error: <driver>: attribute 'period' must be at least 1, got 0"));
    CHECK(text.find("'period'") == text.rfind("'period'"));  // said once
  }
  // a model made in code: the builder says it
  SceneModel model = parseSceneString(xml.substr(0, xml.find("<driver")) + "</artifact></scene>", "memory.xml",
                                      test::kArtifacts, testOptions());
  auto driver = std::make_shared<Descriptor>("driver", SourceLocation{"code.xml", 9});
  driver->set("period", "-2", SourceLocation{"code.xml", 9});
  model.placements.at(0).driver = driver;
  CHECK_THROWS_WITH(buildScene(model, testOptions()),
                    Contains("code.xml:9: error: <driver>: attribute 'period' must be at least 1, got -2"));
}
