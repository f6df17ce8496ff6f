// The scene as a value: parsed without plugins, printed back to XML, compared, built.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace ssx;
namespace fs = std::filesystem;

namespace {

const fs::path kData = SSX_TEST_DATA_DIR;
const fs::path kExamples = SSX_EXAMPLES_DIR;

SceneOptions testOptions() {
  SceneOptions o;
  o.plugin_path.emplace_back(SSX_TEST_PLUGIN_DIR);
  o.extensions = false;  // no logger writes, no bridge connects
  return o;
}

// the scenes of the examples (ghosts.xml: real robots) and the valid test data: each is a scene file, not an artifact file
std::vector<fs::path> scenes() {
  std::vector<fs::path> out;
  for (const fs::path& dir : {kExamples / "scenes", kExamples / "hardware_in_the_loop", kData / "valid", kData / "valid" / "render"})
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".xml") continue;
      std::ifstream in(entry.path());
      const std::string text((std::istreambuf_iterator<char>(in)), {});
      if (text.find("<scene") != std::string::npos && entry.path().filename() != "three_errors.xml")
        out.push_back(entry.path());
    }
  return out;
}

// the state hash after `steps`, or what stopped the run (a scene may stop itself: bomb.xml)
std::string hashAfter(Scene& scene, int steps) {
  try {
    scene.environment->step(steps);
    return std::to_string(scene.environment->stateHash());
  } catch (const StepError& e) {
    return e.what();
  }
}

}  // namespace

TEST_CASE("a scene model prints back to XML that parses to an equal model, and builds the same world",
          "[scene][model]") {
  const auto files = scenes();
  REQUIRE(files.size() >= 10);
  for (const fs::path& file : files) {
    INFO(file.string());
    const SceneModel first = parseScene(file, testOptions());
    const std::string xml = first.toXml();
    const SceneModel second = parseSceneString(xml, "printed.xml", file.parent_path(), testOptions());
    CHECK(second == first);
    CHECK(second.toXml() == xml);
    // the printed scene is the same scene: built, both step to the same bits
    Scene a = buildScene(first, testOptions());
    Scene b = buildScene(second, testOptions());
    REQUIRE(a.environment->artifactCount() == b.environment->artifactCount());
    CHECK(hashAfter(a, 20) == hashAfter(b, 20));
  }
}

TEST_CASE("two loads of one file give equal models, a changed value gives another", "[scene][model]") {
  const fs::path file = kExamples / "scenes" / "formation_sphere.xml";
  CHECK(parseScene(file, testOptions()) == parseScene(file, testOptions()));
  SceneOptions seeded = testOptions();
  seeded.seed = 99;
  const SceneModel other = parseScene(file, seeded);
  CHECK_FALSE(other == parseScene(file, testOptions()));
  CHECK(other.settings.seed == 99);
  CHECK(other.toXml().find("seed=\"99\"") != std::string::npos);
}

TEST_CASE("the model holds every default and what the file says, with where it said it", "[scene][model]") {
  const SceneModel m = parseSceneString(
      "<scene>\n<environment timestep=\"0.002\"/>\n<type name=\"ball\" file=\"ball.xml\"/>\n"
      "<swarm type=\"ball\" count=\"4\" name=\"b{i}\" first_index=\"10\" spacing=\"2\" xyz=\"0 0 1\"/>\n"
      "<artifact name=\"one\" type=\"ball\" rpy=\"0 0 1.5\"/>\n<ground/>\n</scene>",
      "mem.xml", kData / "valid", testOptions());
  CHECK(m.settings.timestep == 2'000'000);
  CHECK(m.settings.physics.engine == "ode");
  CHECK(m.settings.physics.ode.iterations == 20);
  // where each setting was written; a default has no place
  REQUIRE(m.settings_from.count("environment@timestep") == 1);
  CHECK(m.settings_from.at("environment@timestep").str() == "mem.xml:2");
  CHECK(m.settings_from.count("physics@engine") == 0);
  REQUIRE(m.placements.size() == 3);
  const PlacementModel& swarm = m.placements[0];
  CHECK(swarm.kind == PlacementModel::Kind::Swarm);
  CHECK(swarm.where.line == 4);
  CHECK(swarm.columns == 2);  // the default: the square root of the count, rounded up
  CHECK(swarm.positions.size() == 4);
  CHECK(swarm.memberName(3) == "b13");
  CHECK(m.placements[1].rpy == Vec3(0, 0, 1.5));
  CHECK(m.placements[2].kind == PlacementModel::Kind::Ground);
  REQUIRE(m.types.count("ball") == 1);
  CHECK(m.types.at("ball").physic.size() == 1);
  const std::string xml = m.toXml();
  CHECK(xml.find("<physics engine=\"ode\" gravity=\"0 0 -9.81\"") != std::string::npos);
  CHECK(xml.find("<swarm type=\"ball\" count=\"4\" name=\"b{i}\" first_index=\"10\" layout=\"grid\"") != std::string::npos);
}

TEST_CASE("parsing loads no plugin, building reports what the plugins say", "[scene][model]") {
  // a plugin that does not exist, and a parameter a plugin declares out of range: neither is the
  // file's own problem, so the model parses; building finds both
  const std::string xml =
      "<scene>\n<type name=\"q\" file=\"" + (kExamples / "artifacts" / "mk_quad.xml").string() +
      "\"/>\n<artifact name=\"q0\" type=\"q\"><driver attitude_kp=\"-1\"/></artifact>\n"
      "<extension name=\"x\" plugin=\"no_such_plugin\"/>\n</scene>";
  SceneOptions options = testOptions();
  options.extensions = true;
  const SceneModel model = parseSceneString(xml, "plugins.xml", kData, options);
  CHECK(model.extensions.size() == 1);
  try {
    (void)buildScene(model, options);
    FAIL("built without error");
  } catch (const SceneError& e) {
    const std::string what = e.what();
    CHECK(what.find("no_such_plugin") != std::string::npos);
    CHECK(what.find("parameter 'attitude_kp' must be > 0") != std::string::npos);
  }
  // loadScene reports the file's own problems and the plugins' together, in document order
  try {
    (void)loadSceneFromString(
        "<scene>\n<environment timestep=\"-1\"/>\n<type name=\"q\" file=\"" +
            (kExamples / "artifacts" / "mk_quad.xml").string() +
            "\"/>\n<artifact name=\"q0\" type=\"q\"><driver attitude_kp=\"-1\"/></artifact>\n"
            "<artifact name=\"q1\" type=\"nothing\"/>\n</scene>",
        "both.xml", kData, options);
    FAIL("loaded without error");
  } catch (const SceneError& e) {
    std::vector<int> lines;
    for (const auto& d : e.diagnostics())
      if (d.severity == Diagnostic::Severity::Error && d.where.file == "both.xml") lines.push_back(d.where.line);
    CHECK(lines == std::vector<int>{2, 4, 5});
  }
}

TEST_CASE("a model made in code builds, a placement of a type it lacks is reported", "[scene][model]") {
  SceneModel model = parseScene(kData / "valid" / "layouts.xml", testOptions());
  PlacementModel extra;
  extra.kind = PlacementModel::Kind::Artifact;
  extra.name = "stray";
  extra.type = "unicorn";
  model.placements.push_back(extra);
  CHECK_THROWS_WITH(buildScene(model, testOptions()), Catch::Contains("unknown artifact type 'unicorn'"));
  model.placements.back().type = "ball";
  model.placements.back().xyz = Vec3(0, 0, 20);
  Scene scene = buildScene(model, testOptions());
  REQUIRE(scene.environment->findArtifact("stray") != nullptr);
  CHECK(scene.environment->findArtifact("stray")->placement().position == Vec3(0, 0, 20));
}

TEST_CASE("a setting an override changed is placed where the override was given", "[scene][model]") {
  SceneOptions options = testOptions();
  options.overrides = {{"environment@seed", "9", {"sweep.xml", 4}},
                       {"render/camera[name=top]@xyz", "1 2 3", {"sweep.xml", 5}}};
  const SceneModel m = parseSceneString("<scene>\n<environment timestep=\"0.002\" seed=\"1\"/>\n"
                                        "<render><camera name=\"top\" xyz=\"0 0 9\"/></render>\n</scene>",
                                        "mem.xml", kData / "valid", options);
  CHECK(m.settings.seed == 9);
  CHECK(m.settings_from.at("environment@seed").str() == "sweep.xml:4");
  CHECK(m.settings_from.at("environment@timestep").str() == "mem.xml:2");
  CHECK(m.settings_from.at("render/camera[name=top]@xyz").str() == "sweep.xml:5");
  CHECK(m.settings_from.at("render/camera[name=top]@name").str() == "mem.xml:3");
}
