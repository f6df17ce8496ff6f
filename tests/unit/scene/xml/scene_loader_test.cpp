// The scene loader: every broken file gives its exact first diagnostic and runs nothing; all problems are
// reported together; what it does not understand is a warning with its line; types are found by name.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <regex>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

// the expectation written on the first line of each broken file: <!-- expect: ... -->
std::string expectation(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  const auto begin = line.find("expect: ");
  const auto end = line.rfind(" -->");
  REQUIRE(begin != std::string::npos);
  return line.substr(begin + 8, end - begin - 8);
}

// the first error line, with the data directory and absolute plugin paths taken out
std::string firstError(const SceneError& e, const fs::path& dir) {
  for (const auto& d : e.diagnostics()) {
    if (d.severity != Diagnostic::Severity::Error) continue;
    std::string s = d.str();
    const std::string prefix = dir.string() + "/";
    for (auto at = s.find(prefix); at != std::string::npos; at = s.find(prefix)) s.erase(at, prefix.size());
    return std::regex_replace(s, std::regex(" \\(/[^)]*\\)"), "");
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("every broken scene reports its exact file:line: error: and runs nothing", "[scene]") {
  const fs::path dir = kData / "invalid";
  fs::remove("marker_ran.txt");
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".xml") continue;
    ++files;
    const std::string expected = expectation(entry.path());
    INFO(entry.path().filename().string());
    try {
      (void)loadScene(entry.path(), testOptions());
      FAIL("loaded without error");
    } catch (const SceneError& e) {
      const std::string got = firstError(e, dir);
      CHECK(got.substr(0, expected.size()) == expected);
      CHECK_THAT(e.what(), Catch::EndsWith("nothing was run"));
    }
  }
  CHECK(files >= 25);
  // the scenes' marker extension writes this file if any of them was ever initialised
  CHECK_FALSE(fs::exists("marker_ran.txt"));
}

TEST_CASE("all problems of a scene are reported together, in document order", "[scene]") {
  try {
    (void)loadScene(kData / "valid" / "three_errors.xml", testOptions());
    FAIL("loaded without error");
  } catch (const SceneError& e) {
    std::vector<std::string> errors;
    for (const auto& d : e.diagnostics())
      if (d.severity == Diagnostic::Severity::Error) errors.push_back(std::to_string(d.where.line) + " " + d.message);
    REQUIRE(errors.size() == 3);
    CHECK_THAT(errors[0], Catch::StartsWith("2 <environment>: attribute 'timestep' must be positive"));
    CHECK_THAT(errors[1], Catch::StartsWith("2 <environment>: attribute 'seed' must be a whole number from 0 to 18446744073709551615, got 'x'"));
    CHECK_THAT(errors[2], Catch::StartsWith("5 <swarm>: attribute 'layout' must be one of"));
  }
}

TEST_CASE("unknown elements, attributes and plugin parameters are warnings with their lines", "[scene]") {
  Scene scene = loadScene(kData / "valid" / "warnings.xml", testOptions());
  std::vector<std::string> warnings;
  for (const auto& w : scene.warnings) warnings.push_back(w.str().substr(w.str().rfind('/') + 1));
  // the plugin's parameters are known from its declarations while loading, before anything runs
  CHECK(warnings ==
        std::vector<std::string>{"warnings.xml:2: warning: unknown attribute 'colour' of <environment> (ignored)",
                                 "warnings.xml:5: warning: unknown element <lights> in <scene> (ignored)",
                                 "spinner.xml:5: warning: unknown parameter 'torqeu' of driver 'spinner' (ignored; "
                                 "did you mean 'torque'?)"});
  // and are not reported a second time when the environment starts
  std::vector<std::string> logged;
  scene.environment->setLogSink([&](LogLevel, std::string_view m) { logged.emplace_back(m.substr(m.rfind('/') + 1)); });
  scene.environment->start();
  CHECK(logged.empty());
  scene.environment->step(11);
  // and the one it knows took effect: 0.5 N m on Izz = 1/600 for 10 steps of 10 ms
  CHECK(scene.environment->findArtifact("s")->state().angular_velocity.z() == Approx(0.5 * 600 * 0.1).epsilon(1e-9));
}

TEST_CASE("scenes load from memory with paths relative to a base directory", "[scene]") {
  const std::string xml = R"(<scene>
    <type name="box" file="parts/box.xml"/>
    <artifact name="b" type="box" xyz="1 2 3" rpy="0 0 1.5707963267948966"/>
  </scene>)";
  Scene scene = loadSceneFromString(xml, "memory.xml", kData / "invalid", testOptions());
  const Pose p = scene.environment->findArtifact("b")->pose();
  CHECK(p.position.isApprox(Vec3(1, 2, 3)));
  CHECK((p.orientation * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-12));
  CHECK_THROWS_WITH(loadSceneFromString("<scene><artifact/>", "memory.xml", ".", testOptions()),
                    Catch::StartsWith("memory.xml:1: error: XML syntax"));
}

TEST_CASE("counts have upper bounds", "[scene]") {
  const std::string xml = R"(<scene>
    <physics partitions="4000" max_contacts="100000000" broadphase="sap"/>
    <type name="box" file="parts/box.xml"/>
    <swarm type="box" count="1000000000000"/>
  </scene>)";
  try {
    (void)loadSceneFromString(xml, "m.xml", kData / "invalid", testOptions());
    FAIL("loaded");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(),
               Catch::Contains("m.xml:2: error: <physics>: ode engine: parameter 'partitions' must be >= 1 and <= 1024, got '4000'"));
    // ODE's broadphases are gone: a scene that names one is told so
    CHECK_THAT(e.what(), Catch::Contains("m.xml:2: error: <physics>: attribute 'broadphase' is no longer offered"));
    CHECK_THAT(e.what(), Catch::Contains("parameter 'max_contacts' must be >= 1 and <= 1024"));
    CHECK_THAT(e.what(), Catch::Contains("m.xml:4: error: <swarm>: attribute 'count' must be at most 10000000"));
  }
}

TEST_CASE("the default demo scene loads without warnings", "[scene]") {
  Scene scene = loadScene(fs::path(SSX_EXAMPLES_DIR) / "scenes" / "quad_swarm.xml");
  CHECK(scene.warnings.empty());
  CHECK(scene.environment->artifactCount() == 27);
  CHECK(scene.duration == toNanoseconds(20.0));
}

TEST_CASE("a type named without a file is the installed artifact type, a given file or directory wins", "[scene]") {
  // the build tree mirrors the installation: <build>/share/ssx/artifacts
  const fs::path data = installedDataDirectory();
  REQUIRE_FALSE(data.empty());
  REQUIRE(fs::is_regular_file(data / "artifacts" / "mk_quad.xml"));
  REQUIRE(fs::is_regular_file(data / "scenes" / "quad_swarm.xml"));

  const std::string by_name = R"(<scene>
    <type name="mk_quad"/>
    <artifact name="q" type="mk_quad" xyz="0 0 1"/>
  </scene>)";
  {
    Scene scene = loadSceneFromString(by_name, "m.xml", "/nonexistent");
    const Artifact& q = *scene.environment->findArtifact("q");
    REQUIRE(q.driver() != nullptr);
    CHECK(q.driver()->className() == "quadrotor");
    CHECK(q.sensorCount() == 2);
  }

  // a directory of the caller's, holding its own mk_quad.xml (here: a passive box), comes first
  const fs::path dir = fs::current_path() / "installed_type_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(fs::path(SSX_EXAMPLES_DIR) / "artifacts" / "box.xml", dir / "mk_quad.xml");
  SceneOptions options;
  options.artifact_path.push_back(dir);
  {
    Scene scene = loadSceneFromString(by_name, "m.xml", "/nonexistent", options);
    CHECK(scene.environment->findArtifact("q")->driver() == nullptr);
  }
  // a scene-relative file wins over every directory
  {
    Scene scene = loadSceneFromString(R"(<scene><type name="mk_quad" file="mk_quad.xml"/>
      <artifact name="q" type="mk_quad"/></scene>)", "m.xml", dir);
    CHECK(scene.environment->findArtifact("q")->driver() == nullptr);
  }
  // an unknown name says where it looked and what to do
  try {
    (void)loadSceneFromString(R"(<scene>
      <type name="no_such_robot"/><type name="../mk_quad"/><type name="e" file=""/>
    </scene>)", "m.xml", dir, options);
    FAIL("loaded");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Contains("m.xml:2: error: <type>: no 'file' given and no installed artifact type "
                                  "'no_such_robot' (looked for no_such_robot.xml in " + dir.string() + ", " +
                                  (data / "artifacts").string() + "); give file="));
    CHECK_THAT(e.what(), Contains("no installed artifact type '../mk_quad'"));
    CHECK_THAT(e.what(), Contains("m.xml:2: error: <type>: attribute 'file' is empty"));
  }
  fs::remove_all(dir);
}

TEST_CASE("a timestep finer than a nanosecond is a warning saying what it became, seeds are 0 to 2^64 - 1", "[scene]") {
  Scene scene = loadSceneFromString(R"(<scene>
    <environment timestep="1.5e-9" seed="18446744073709551615"/></scene>)", "t.xml", kData);
  REQUIRE(scene.warnings.size() == 1);
  CHECK(scene.warnings[0].str() == "t.xml:2: warning: <environment>: timestep 1.5e-9 s is 2 ns (time is counted in whole nanoseconds)");
  CHECK(scene.environment->timestep() == 2);
  CHECK(scene.environment->settings().seed == kMaxSeed);
  CHECK(loadSceneFromString(R"(<scene><environment timestep="0.002"/></scene>)", "t.xml", kData).warnings.empty());
  // the scene took seeds up to 1e7 only, while the command line, Python and sweeps took any
  CHECK(loadSceneFromString(R"(<scene><environment seed="12345678901234"/></scene>)", "t.xml", kData)
            .environment->settings().seed == 12345678901234u);
  for (const char* bad : {"18446744073709551616", "-1", "0x10", "1e3", "7 "})
    CHECK_THROWS_WITH(loadSceneFromString(std::string("<scene><environment seed=\"") + bad + "\"/></scene>", "t.xml", kData),
                      Contains("t.xml:1: error: <environment>: attribute 'seed' must be a whole number from 0 to "
                               "18446744073709551615, got '" + std::string(bad) + "'"));
}

TEST_CASE("an unknown name near a known one asks whether that was meant", "[scene]") {
  Scene scene = loadSceneFromString(R"(<scene>
    <environment timestpe="0.002" duraton="3"/>
    <swram type="ball" count="2"/>
    <type name="ball" file="ball.xml"/><artifact name="b" type="ball" xyz="0 0 1" rpy_="0 0 0"/>
  </scene>)", "m.xml", kData / "valid", testOptions());
  std::vector<std::string> warnings;
  for (const auto& w : scene.warnings) warnings.push_back(w.str());
  CHECK(warnings == std::vector<std::string>{
                        "m.xml:2: warning: unknown attribute 'timestpe' of <environment> (ignored; did you mean 'timestep'?)",
                        "m.xml:2: warning: unknown attribute 'duraton' of <environment> (ignored; did you mean 'duration'?)",
                        "m.xml:3: warning: unknown element <swram> in <scene> (ignored; did you mean 'swarm'?)",
                        "m.xml:4: warning: unknown attribute 'rpy_' of <artifact> (ignored; did you mean 'rpy'?)"});
  CHECK_THROWS_WITH(loadSceneFromString(R"(<scene><extension name="log" plugin="csv_loger" file="x.csv"/></scene>)", "m.xml",
                                        kData / "valid"),
                    Contains("plugin 'csv_loger' could not be loaded (did you mean 'csv_logger'?); tried:"));
  // nothing near: no guess
  Scene far = loadSceneFromString(R"(<scene><environment colour="red"/></scene>)", "m.xml", kData / "valid");
  REQUIRE(far.warnings.size() == 1);
  CHECK_THAT(far.warnings[0].str(), !Contains("did you mean"));
}
