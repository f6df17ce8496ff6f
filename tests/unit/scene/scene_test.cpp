// Loading entry points (scene.cpp): one error holding every diagnostic, a file that cannot be read
// reported as a diagnostic, relative paths from the scene's directory, and warnings carried from
// parsing through building.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

using namespace ssx;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("a scene error lists each diagnostic on its line, then how many were errors", "[scene]") {
  const SceneError e({{Diagnostic::Severity::Warning, {"s.xml", 2}, "unknown attribute 'x' (ignored)"},
                      {Diagnostic::Severity::Error, {"s.xml", 4}, "attribute 'count' must be positive"},
                      {Diagnostic::Severity::Error, {"t.xml", 1}, "XML syntax error"}});
  CHECK(std::string(e.what()) ==
        "s.xml:2: warning: unknown attribute 'x' (ignored)\n"
        "s.xml:4: error: attribute 'count' must be positive\n"
        "t.xml:1: error: XML syntax error\n"
        "2 error(s); nothing was run");
  CHECK(e.diagnostics().size() == 3);
}

TEST_CASE("a scene file that cannot be read is a diagnostic naming it", "[scene]") {
  const fs::path missing = fs::current_path() / "no_such_scene.xml";
  fs::remove(missing);
  try {
    (void)loadScene(missing);
    FAIL("loaded");
  } catch (const SceneError& e) {
    REQUIRE(e.diagnostics().size() == 1);
    CHECK(e.diagnostics()[0].where.file == missing.string());
    CHECK_THAT(e.what(), Contains(missing.string()) && Contains("nothing was run"));
  }
  CHECK_THROWS_AS(parseScene(missing, {}), SceneError);
}

TEST_CASE("a scene's files are found from its own directory, wherever the program runs", "[scene]") {
  const fs::path dir = fs::current_path() / "scene_dir_test";
  fs::remove_all(dir);
  fs::create_directories(dir / "parts");
  fs::copy_file(test::kArtifacts / "box.xml", dir / "parts" / "crate.xml");
  std::ofstream(dir / "scene.xml") << R"(<scene><type name="crate" file="parts/crate.xml"/>
    <artifact name="c" type="crate" xyz="0 0 3"/></scene>)";
  Scene scene = loadScene(dir / "scene.xml");
  CHECK(scene.environment->findArtifact("c")->pose().position.z() == 3);
  // the files the scene read: the scene and its type, by their paths
  const auto has = [&](const fs::path& p) {
    for (const auto& f : scene.files.inputs())
      if (fs::equivalent(f, p)) return true;
    return false;
  };
  CHECK(has(dir / "scene.xml"));
  CHECK(has(dir / "parts" / "crate.xml"));
  fs::remove_all(dir);
}

TEST_CASE("warnings found while parsing are the built scene's warnings too", "[scene]") {
  const std::string xml = R"(<scene>
    <environment colour="red"/><type name="box" file="box.xml"/><artifact name="b" type="box"/></scene>)";
  const SceneModel model = parseSceneString(xml, "w.xml", test::kArtifacts, {});
  REQUIRE(model.warnings.size() == 1);
  CHECK_THAT(model.warnings[0].str(), Contains("w.xml:2: warning: unknown attribute 'colour'"));
  const Scene scene = buildScene(model, {});
  REQUIRE(scene.warnings.size() == 1);
  CHECK(scene.warnings[0].str() == model.warnings[0].str());
  // loading in one go says the same
  CHECK(loadSceneFromString(xml, "w.xml", test::kArtifacts).warnings.size() == 1);
}
