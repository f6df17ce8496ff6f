// csv_logger: rows at its rate, flushed at its simulated interval, names quoted, failed writes stop the run.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

using namespace ssx;
using ssx::test::kData;
using Catch::Contains;
namespace fs = std::filesystem;

using ssx::test::fileLines;

namespace {
// dir/pendulum.xml: an arm hinged about y to a static base (with `base_shapes`), turned 1 rad,
// its 1 kg bob 1 m below the pivot
void writePendulum(const fs::path& dir, const std::string& base_shapes) {
  fs::create_directories(dir);
  std::ofstream(dir / "pendulum.xml") << R"(<artifact>
  <physic name="base" static="true">)" << base_shapes << R"(
    <physic name="arm" joint="hinge" axis="0 1 0" rpy="0 1 0" mass="1"><sphere radius="0.05" xyz="0 0 -1"/></physic>
  </physic>
</artifact>
)";
}
std::string loggerScene(const std::string& file, const std::string& flush_s) {
  return R"(<scene><environment timestep="0.01"/><type name="ball" file="ball.xml"/>
    <artifact name="b" type="ball" xyz="0 0 1"/>
    <extension name="log" plugin="csv_logger" file=")" +
         file + R"(" rate_hz="100" flush_s=")" + flush_s + R"("/></scene>)";
}
}  // namespace

TEST_CASE("csv_logger flushes at its simulated interval and when the run stops", "[scene][csv]") {
  Scene scene = loadSceneFromString(loggerScene("log.csv", "0.1"), "memory.xml", kData / "valid");
  Environment& env = *scene.environment;
  env.step(5);  // t = 0.05 s: nothing flushed yet
  CHECK(fs::file_size("log.csv") == 0);
  env.step(7);  // t = 0.12 s: flushed at 0.1 s, before that step's row: the header and 0.01 ... 0.09 s
  std::vector<std::string> rows = fileLines("log.csv");
  REQUIRE(rows.size() == 1 + 9);
  CHECK(rows.back().rfind("0.09,b,", 0) == 0);
  env.stop();
  rows = fileLines("log.csv");
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
  const auto rows = fileLines("quoted.csv");
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

TEST_CASE("csv_logger: bodies=\"all\" logs every body of an artifact, joined children as artifact/node", "[scene][csv][joints]") {
  writePendulum("csv_joints", "");
  Scene scene = loadSceneFromString(R"(<scene><environment timestep="0.01"/><type name="p" file="pendulum.xml"/>
    <artifact name="p" type="p" xyz="0 0 2"/>
    <extension name="log" plugin="csv_logger" file="bodies.csv" bodies="all" artifacts="p"/></scene>)",
                                    "memory.xml", fs::current_path() / "csv_joints");
  Environment& env = *scene.environment;
  env.step(50);
  const Vec3 arm = env.findArtifact("p")->node("arm")->pose().position;
  env.stop();
  const auto rows = fileLines("bodies.csv");
  REQUIRE(rows.size() == 1 + 2 * 50);  // the static root's row and the arm's, each step
  CHECK(rows[99].rfind("0.5,p,", 0) == 0);
  REQUIRE(rows[100].rfind("0.5,p/arm,", 0) == 0);
  // the arm's row is the arm's pose
  char name[64];
  double t, x, y, z;
  REQUIRE(std::sscanf(rows[100].c_str(), "%lf,%63[^,],%lf,%lf,%lf", &t, name, &x, &y, &z) == 5);
  CHECK(Vec3(x, y, z).isApprox(arm, 1e-6));
}

TEST_CASE("csv_logger, recorder: a static-rooted articulation's moving parts are logged and recorded, its base not",
          "[scene][csv][joints][record]") {
  // a pendulum on a fixed pivot (a door, an arm on a table): before, artifacts="*" and recordings
  // left out the whole artifact, since its root does not move
  writePendulum("csv_static_root", R"(<box size="0.1 0.1 0.1"/>)");
  Scene scene = loadSceneFromString(R"(<scene><environment timestep="0.01"/><type name="p" file="pendulum.xml"/>
    <artifact name="p" type="p" xyz="0 0 2"/>
    <extension name="log" plugin="csv_logger" file="moving.csv" bodies="all"/></scene>)",
                                    "memory.xml", fs::current_path() / "csv_static_root");
  Environment& env = *scene.environment;
  RecordOptions record;
  record.file = fs::current_path() / "csv_static_root" / "moving.mcap";
  record.scene_xml = scene.model->toXml();
  record.rate_hz = 100;  // every step
  Recorder recorder(env, record);
  env.step(50);
  const PhysicNode& arm = *env.findArtifact("p")->node("arm");
  CHECK(recorder.finish().bodies == 1);
  env.stop();
  const auto rows = fileLines("moving.csv");
  REQUIRE(rows.size() == 1 + 50);  // the arm's row each step, none for the base
  REQUIRE(rows[50].rfind("0.5,p/arm,", 0) == 0);
  const Recording r(record.file);
  REQUIRE(r.names() == std::vector<std::string>{"p/arm"});
  // the arm as it turned: it swung (from where it was placed, 1 rad out) and the recording has it
  CHECK(arm.jointPosition() < -0.1);
  const std::vector<float> q = r.orientations(r.times().size() - 1);
  const Quat& o = arm.pose().orientation;
  CHECK(std::abs(q[0] * o.w() + q[1] * o.x() + q[2] * o.y() + q[3] * o.z()) > 1 - 1e-6);
}

TEST_CASE("csv_logger: joints=\"true\" adds each body's joint position and velocity, empty for a body without one",
          "[scene][csv][joints]") {
  writePendulum("csv_joint_columns", R"(<box size="0.1 0.1 0.1"/>)");
  const std::string scene_text = R"(<scene><environment timestep="0.01"/><type name="p" file="pendulum.xml"/>
    <type name="ball" file=")" + (fs::path(kData) / "valid" / "ball.xml").string() + R"("/>
    <artifact name="p" type="p" xyz="0 0 2"/><artifact name="b" type="ball" xyz="3 0 1"/>
    <extension name="log" plugin="csv_logger" file="joints.csv" bodies="all" joints="true"/></scene>)";
  Scene scene = loadSceneFromString(scene_text, "memory.xml", fs::current_path() / "csv_joint_columns");
  Environment& env = *scene.environment;
  env.step(50);
  const PhysicNode& arm = *env.findArtifact("p")->node("arm");
  const double position = arm.jointPosition(), velocity = arm.jointVelocity();
  env.stop();
  const auto rows = fileLines("joints.csv");
  REQUIRE(rows[0] == "time_s,artifact,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,joint_position,joint_velocity");
  REQUIRE(rows.size() == 1 + 2 * 50);  // the arm and the ball, each step
  const std::string& last_arm = rows[rows.size() - 2];
  REQUIRE(last_arm.rfind("0.5,p/arm,", 0) == 0);
  const std::string joints = last_arm.substr(last_arm.find(',', last_arm.find(',') + 1));
  double columns[15] = {};
  REQUIRE(std::sscanf(joints.c_str(), ",%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &columns[0],
                      &columns[1], &columns[2], &columns[3], &columns[4], &columns[5], &columns[6], &columns[7],
                      &columns[8], &columns[9], &columns[10], &columns[11], &columns[12], &columns[13],
                      &columns[14]) == 15);
  CHECK(columns[13] == Approx(position).margin(1e-8));
  CHECK(columns[14] == Approx(velocity).margin(1e-8));
  CHECK(std::abs(position) > 0.1);  // it swung
  // the ball is a body of its own, joined to nothing: its joint columns are empty
  CHECK(rows.back().rfind("0.5,b,", 0) == 0);
  CHECK(rows.back().substr(rows.back().size() - 2) == ",,");
  // joints without bodies="all": refused at its attribute, before anything is written
  const std::string root_only = R"(<scene><environment timestep="0.01"/><type name="p" file="pendulum.xml"/>
    <artifact name="p" type="p" xyz="0 0 2"/>
    <extension name="log" plugin="csv_logger" file="refused.csv" joints="true"/></scene>)";
  CHECK_THROWS_WITH(loadSceneFromString(root_only, "memory.xml", fs::current_path() / "csv_joint_columns"),
                    Contains("joints=\"true\" logs the joints of an artifact's bodies: give bodies=\"all\" too"));
  CHECK_FALSE(fs::exists("refused.csv"));
}
