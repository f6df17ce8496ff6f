// Scene files: every broken file gives its exact first diagnostic and runs nothing; valid files
// load, warn about what they do not understand, and run reproducibly.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>
#include <dlfcn.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

using namespace ssx;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

const fs::path kData = SSX_TEST_DATA_DIR;

SceneOptions testOptions() {
  SceneOptions o;
  o.plugin_path.emplace_back(SSX_TEST_PLUGIN_DIR);
  return o;
}

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
    CHECK_THAT(errors[1], Catch::StartsWith("2 <environment>: attribute 'seed' must be an integer"));
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
                                 "it has: torque)"});
  // and are not reported a second time when the environment starts
  std::vector<std::string> logged;
  scene.environment->setLogSink([&](LogLevel, std::string_view m) { logged.emplace_back(m.substr(m.rfind('/') + 1)); });
  scene.environment->start();
  CHECK(logged.empty());
  scene.environment->step(11);
  // and the one it knows took effect: 0.5 N m on Izz = 1/600 for 10 steps of 10 ms
  CHECK(scene.environment->findArtifact("s")->state().angular_velocity.z() == Approx(0.5 * 600 * 0.1).epsilon(1e-9));
}

TEST_CASE("swarm layouts place artifacts on a grid, on a Fibonacci sphere and at seeded random", "[scene]") {
  Scene scene = loadScene(kData / "valid" / "layouts.xml", testOptions());
  Environment& env = *scene.environment;
  CHECK(env.artifactCount() == 70 + 12 + 50 + 1);
  // sphere: every robot 4 m from the centre; neighbours 1.48 to 1.65 m apart for N = 70
  double nearest_min = 1e9, nearest_max = 0;
  for (int i = 0; i < 70; ++i) {
    const Vec3 p = env.findArtifact("s" + std::to_string(i))->pose().position;
    CHECK((p - Vec3(0, 0, 5)).norm() == Approx(4.0).epsilon(1e-9));
    double nearest = 1e9;
    for (int j = 0; j < 70; ++j)
      if (j != i) nearest = std::min(nearest, (p - env.findArtifact("s" + std::to_string(j))->pose().position).norm());
    nearest_min = std::min(nearest_min, nearest);
    nearest_max = std::max(nearest_max, nearest);
  }
  CHECK(nearest_min > 1.3);
  CHECK(nearest_max < 1.8);
  // grid: 4 columns along x, spacing 2
  CHECK(env.findArtifact("g5")->pose().position.isApprox(Vec3(12, 2, 0)));
  // random: inside the box, and the same for the same seed
  for (int i = 0; i < 50; ++i) {
    const Vec3 p = env.findArtifact("r" + std::to_string(i))->pose().position;
    CHECK(p.x() >= -20);
    CHECK(p.x() <= -10);
    CHECK(p.y() <= -15);
    CHECK(p.z() >= 1);
  }
  Scene again = loadScene(kData / "valid" / "layouts.xml", testOptions());
  CHECK(again.environment->findArtifact("r7")->pose().position == env.findArtifact("r7")->pose().position);
  SceneOptions other = testOptions();
  other.seed = 6;
  Scene reseeded = loadScene(kData / "valid" / "layouts.xml", other);
  CHECK(reseeded.environment->findArtifact("r7")->pose().position != env.findArtifact("r7")->pose().position);
  // the included fragment's obstacle
  CHECK(env.findArtifact("pillar") != nullptr);
  CHECK(env.findArtifact("pillar")->root().isStatic());
}

TEST_CASE("a scene with plugins runs bitwise identically on 1 and 2 threads", "[scene][determinism]") {
  auto hashAfter = [](int threads) {
    SceneOptions o = testOptions();
    o.threads = threads;
    Scene scene = loadScene(kData / "valid" / "layouts.xml", o);
    scene.environment->step(200);
    return scene.environment->stateHash();
  };
  CHECK(hashAfter(1) == hashAfter(2));
}

TEST_CASE("the example scene loads, flies and logs", "[scene]") {
  fs::remove("hover_swarm_poses.csv");
  Scene scene = loadScene(fs::path(SSX_EXAMPLES_DIR) / "scenes" / "hover_swarm.xml");
  CHECK(scene.warnings.empty());
  CHECK(scene.duration == toNanoseconds(10.0));
  Environment& env = *scene.environment;
  CHECK(env.artifactCount() == 25 + 4 + 2 + 1);
  env.step(2500);  // 5 s
  // every robot holds 1 m above where it started (pose noise 2 mm)
  for (int i = 0; i < 25; ++i)
    CHECK(env.findArtifact("robot" + std::to_string(i))->pose().position.z() == Approx(1.05).margin(0.02));
  env.stop();
  std::ifstream csv("hover_swarm_poses.csv");
  std::string header;
  std::getline(csv, header);
  CHECK(header == "time_s,artifact,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz");
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  CHECK(rows == 3 * 250);  // three robots at 50 Hz for 5 s
}

namespace {
std::string loggerScene(const std::string& file, const std::string& flush_s) {
  return R"(<scene><environment timestep="0.01"/><type name="ball" file="ball.xml"/>
    <artifact name="b" type="ball" xyz="0 0 1"/>
    <extension name="log" plugin="csv_logger" file=")" +
         file + R"(" rate_hz="100" flush_s=")" + flush_s + R"("/></scene>)";
}
std::vector<std::string> lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}
}  // namespace

TEST_CASE("csv_logger flushes at its simulated interval and when the run stops", "[scene][csv]") {
  Scene scene = loadSceneFromString(loggerScene("log.csv", "0.1"), "memory.xml", kData / "valid");
  Environment& env = *scene.environment;
  env.step(5);  // t = 0.05 s: nothing flushed yet
  CHECK(fs::file_size("log.csv") == 0);
  env.step(7);  // t = 0.12 s: flushed at 0.1 s, before that step's row: the header and 0.01 ... 0.09 s
  std::vector<std::string> rows = lines("log.csv");
  REQUIRE(rows.size() == 1 + 9);
  CHECK(rows.back().rfind("0.09,b,", 0) == 0);
  env.stop();
  rows = lines("log.csv");
  REQUIRE(rows.size() == 1 + 12);
  CHECK(rows.back().rfind("0.12,b,", 0) == 0);
}

TEST_CASE("csv_logger quotes names that hold a comma, a quote or a line break", "[scene][csv]") {
  Scene scene = loadSceneFromString(R"(<scene><environment timestep="0.01"/><type name="ball" file="ball.xml"/>
    <artifact name="a,&quot;b&quot;" type="ball" xyz="0 0 1"/>
    <extension name="log" plugin="csv_logger" file="quoted.csv" rate_hz="100"/></scene>)",
                                    "memory.xml", kData / "valid");
  scene.environment->step(2);
  scene.environment->stop();
  const auto rows = lines("quoted.csv");
  REQUIRE(rows.size() == 3);
  CHECK(rows[1].rfind("0.01,\"a,\"\"b\"\"\",", 0) == 0);
  CHECK(std::count(rows[1].begin(), rows[1].end(), ',') == 15);  // 14 separators + the one in the name
}

TEST_CASE("csv_logger: a write that fails stops the run naming the file", "[scene][csv]") {
  REQUIRE(fs::exists("/dev/full"));  // writes there fail with ENOSPC, as on a full disk
  SECTION("at a flush while running") {
    SceneOptions streams;
    streams.allow_special_outputs = true;  // a device, written as a stream
    Scene scene = loadSceneFromString(loggerScene("/dev/full", "0.05"), "memory.xml", kData / "valid", streams);
    try {
      scene.environment->step(10);
      FAIL("no StepError");
    } catch (const StepError& e) {
      CHECK(e.step() == 4);  // the step that ends at t = 0.05 s
      CHECK_THAT(e.what(), Contains("cannot write '/dev/full'") && Contains("No space left on device"));
    }
    // reported once: the file is closed, stopping has nothing more to say
    CHECK_NOTHROW(scene.environment->stop());
  }
  SECTION("at the end of the run") {
    SceneOptions streams;
    streams.allow_special_outputs = true;
    Scene scene = loadSceneFromString(loggerScene("/dev/full", "100"), "memory.xml", kData / "valid", streams);
    scene.environment->step(10);
    CHECK_THROWS_WITH(scene.environment->stop(),
                      Contains("extension 'log'") && Contains("cannot write '/dev/full'") &&
                          Contains("No space left on device"));
  }
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

TEST_CASE("a plugin's validate works out what a swarm's members share once per scene load", "[scene][plugins]") {
  // the test plugin's spinner counts how often its validate makes its shared value (per torque)
  void* library = dlopen((fs::path(SSX_TEST_PLUGIN_DIR) / "libssx_test_good.so").c_str(), RTLD_NOW);
  REQUIRE(library != nullptr);
  const auto made = reinterpret_cast<int (*)()>(dlsym(library, "ssx_test_spinner_checks"));
  REQUIRE(made != nullptr);
  const std::string xml = R"(<scene>
    <type name="spinner" file="spinner.xml"/>
    <swarm type="spinner" count="5" name="a{i}" spacing="1"><driver torque="0.2"/></swarm>
    <swarm type="spinner" count="3" name="b{i}" spacing="1"><driver torque="1.{i}"/></swarm>
  </scene>)";
  const int before = made();
  (void)loadSceneFromString(xml, "memory.xml", kData / "valid", testOptions());
  CHECK(made() - before == 4);  // 0.2 once for five members, then 1.0, 1.1 and 1.2
  (void)loadSceneFromString(xml, "memory.xml", kData / "valid", testOptions());
  CHECK(made() - before == 8);  // each load has its own table
  // what the shared check refuses is reported where the value was given
  CHECK_THROWS_WITH(loadSceneFromString(R"(<scene>
    <type name="spinner" file="spinner.xml"/>
    <swarm type="spinner" count="3" name="c{i}" spacing="1"><driver torque="2000"/></swarm>
  </scene>)",
                                        "memory.xml", kData / "valid", testOptions()),
                    Contains("memory.xml:3: error: <driver>: driver 'spinner': torque above 1000 N m"));
  dlclose(library);
}

TEST_CASE("a swarm's members share their type's physic and render trees: one copy whatever the count", "[scene]") {
  const std::string xml = R"(<scene>
    <type name="quad" file="mk_quad.xml"/>
    <swarm type="quad" count="3" name="q{i}" spacing="2"/>
    <artifact name="solo" type="quad" xyz="0 -5 0"/>
  </scene>)";
  Scene scene = loadSceneFromString(xml, "memory.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts", testOptions());
  Environment& env = *scene.environment;
  const Artifact& a = *env.findArtifact("q0");
  REQUIRE(a.renderRoots().size() >= 1);
  for (const char* name : {"q1", "q2", "solo"}) {
    const Artifact& b = *env.findArtifact(name);
    REQUIRE(b.renderRoots().size() == a.renderRoots().size());
    for (std::size_t i = 0; i < a.renderRoots().size(); ++i) CHECK(b.renderRoots()[i].get() == a.renderRoots()[i].get());
  }
  // a tree added by value is the artifact's own; a null tree is refused
  Artifact& extra = env.addArtifact("extra", Pose{});
  RenderNodeSpec ball;
  ball.primitive = RenderNodeSpec::Primitive::Sphere;
  extra.addRenderRoot(ball);
  REQUIRE(extra.renderRoots().size() == 1);
  CHECK(extra.renderRoots()[0]->primitive == RenderNodeSpec::Primitive::Sphere);
  CHECK_THROWS_WITH(extra.addRenderRoot(std::shared_ptr<const RenderNodeSpec>()), Catch::Contains("null render node tree"));
}

TEST_CASE("a node's pose in its body is its type's, to the bit, wherever the artifact was placed", "[scene]") {
  const std::string xml = R"(<scene>
    <type name="quad" file="mk_quad.xml"/>
    <artifact name="here" type="quad"/>
    <artifact name="there" type="quad" xyz="123.4 -56.7 8.9" rpy="0.3 0.2 1.1"/>
  </scene>)";
  Scene scene = loadSceneFromString(xml, "placed.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts", testOptions());
  Environment& env = *scene.environment;
  // known from loading on (a quadrotor's load-time checks read its rotors'), and the same after start
  const Vec3 loaded = env.findArtifact("there")->node("rotor1")->poseInBody().position;
  env.start();
  CHECK(env.findArtifact("there")->node("rotor1")->poseInBody().position == loaded);
  for (const char* node : {"rotor0", "rotor1", "rotor2", "rotor3"}) {
    const Pose& here = env.findArtifact("here")->node(node)->poseInBody();
    const Pose& there = env.findArtifact("there")->node(node)->poseInBody();
    INFO(node);
    CHECK(here.position == there.position);
    CHECK(here.orientation.coeffs() == there.orientation.coeffs());
  }
  // mk_quad's centre of mass is its root's origin: the rotors sit where the file puts them
  CHECK(env.findArtifact("there")->node("rotor1")->poseInBody().position == Vec3(0, 0.225, 0.02));
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
               Catch::Contains("m.xml:2: error: <physics>: attribute 'partitions' must be at most 1024, got 4000"));
    // ODE's broadphases are gone: a scene that names one is told so
    CHECK_THAT(e.what(), Catch::Contains("m.xml:2: error: <physics>: attribute 'broadphase' is no longer offered"));
    CHECK_THAT(e.what(), Catch::Contains("attribute 'max_contacts' must be at most 1024"));
    CHECK_THAT(e.what(), Catch::Contains("m.xml:4: error: <swarm>: attribute 'count' must be at most 10000000"));
  }
}

TEST_CASE("the default demo scene loads without warnings", "[scene]") {
  Scene scene = loadScene(fs::path(SSX_EXAMPLES_DIR) / "scenes" / "quad_swarm.xml");
  CHECK(scene.warnings.empty());
  CHECK(scene.environment->artifactCount() == 27);
  CHECK(scene.duration == toNanoseconds(20.0));
}

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

TEST_CASE("a type named without a file is the installed artifact type; a given file or directory wins", "[scene]") {
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
