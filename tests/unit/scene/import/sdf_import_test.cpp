// Robots from SDFormat (scene/import): the KUKA iiwa's SDF gives the same masses and joints as its
// URDF; the Crazyflie written for Gazebo loads with its COLLADA meshes, its Gazebo plugins and
// sensor listed, flies with ssx's quadrotor driver given in the scene's <type>, and is drawn with
// its mesh.
#include "render_util.hpp"
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>

using namespace ssx;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

const fs::path kRobots = fs::path(SSX_EXAMPLES_DIR) / "robots";
const fs::path kCrazyflie = kRobots / "crazyflie/simulator_files/gazebo/crazyflie/model.sdf";

Scene typeScene(const fs::path& file, const std::string& engine, const std::string& type_children = "",
                const std::string& rest = "", const std::string& placement = "xyz=\"0 0 0\"") {
  const std::string xml = "<scene><environment timestep=\"0.002\" seed=\"1\"/><physics engine=\"" + engine +
                          "\"/><type name=\"robot\" file=\"" + fs::absolute(file).string() + "\">" + type_children +
                          "</type><artifact name=\"r\" type=\"robot\" " + placement + "/>" + rest + "</scene>";
  return loadSceneFromString(xml, "sdf_test.xml", fs::current_path(), test::testOptions());
}

// the Crazyflie's rotors as the SDF names its propeller links, in the firmware's order
const char* kCrazyflieDriver =
    R"(<driver plugin="quadrotor" preset="crazyflie" rotors="crazyflie/m1_prop crazyflie/m2_prop crazyflie/m3_prop crazyflie/m4_prop" directions="-1 1 -1 1"/><sensor plugin="imu"/><sensor plugin="pose"/>)";

}  // namespace

TEST_CASE("The KUKA iiwa from SDF has its URDF's links, masses, inertias and joints", "[import][sdf]") {
  Scene sdf = typeScene(kRobots / "kuka_iiwa/model.sdf", "ode");
  Scene urdf = typeScene(kRobots / "kuka_iiwa/model.urdf", "ode");
  const Artifact& a = *sdf.environment->findArtifact("r");
  const Artifact& b = *urdf.environment->findArtifact("r");
  int joints = 0;
  for (std::size_t i = 0; i < b.nodeCount(); ++i) {
    const PhysicNode& u = b.nodeAt(i);
    CAPTURE(u.name());
    const PhysicNode* s = a.node(u.name());
    REQUIRE(s != nullptr);
    CHECK(s->spec().joint.kind == u.spec().joint.kind);
    if (u.spec().joint.hasPosition()) {
      ++joints;
      CHECK(s->spec().joint.lower == Approx(u.spec().joint.lower));
      CHECK(s->spec().joint.upper == Approx(u.spec().joint.upper));
    }
    if (u.isStatic()) continue;
    const MassProperties ms = bodyMass(s->spec()), mu = bodyMass(u.spec());
    CHECK(ms.mass == Approx(mu.mass));
    // the same link in the world where both were placed
    CHECK((s->pose().position - u.pose().position).norm() < 1e-6);
    // the same joint axis in the world
    if (u.spec().joint.hasPosition()) {
      const Vec3 axis_s = s->pose().orientation * s->spec().joint.axis, axis_u = u.pose().orientation * u.spec().joint.axis;
      CHECK(std::abs(axis_s.dot(axis_u)) > 1 - 1e-6);
    }
  }
  CHECK(joints == 7);
}

TEST_CASE("The Crazyflie's Gazebo model: meshes in, Gazebo's plugins and sensor listed, flown by ssx's driver",
          "[import][sdf][mesh]") {
  for (const std::string engine : {"ode", "bullet"}) {
    CAPTURE(engine);
    Scene scene = typeScene(kCrazyflie, engine, kCrazyflieDriver, "", "xyz=\"0 0 1\"");
    std::string warnings;
    for (const auto& w : scene.warnings) warnings += w.str() + "\n";
    CHECK_THAT(warnings, Contains("model.sdf:") && Contains("gz-sim-multicopter-motor-model-system") &&
                             Contains("a Gazebo plugin is not run by ssx"));
    CHECK_THAT(warnings, Contains("<sensor name=\"multiranger\" type=\"gpu_lidar\"> is Gazebo's"));
    Environment& env = *scene.environment;
    const Artifact& cf = *env.findArtifact("r");
    // the body's mass and full inertia tensor (products too) as the file gives them
    const MassProperties body = bodyMass(cf.node("crazyflie/body")->spec());
    CHECK(body.mass == Approx(0.025));
    CHECK(body.inertia(0, 1) == Approx(0.830806e-6));
    CHECK(body.inertia(1, 2) == Approx(1.800197e-6));
    // it hovers where it was placed, its propellers on their hinges riding along
    env.start();
    for (int i = 0; i < 1500; ++i) env.step();  // 3 s
    const Vec3 p = cf.pose().position;
    CHECK(std::abs(p.z() - (1 + 0.017425)) < 0.05);
    CHECK(p.head<2>().norm() < 0.05);
  }
}

TEST_CASE("The Crazyflie's COLLADA mesh is drawn in a picture", "[import][sdf][mesh][render]") {
  REQUIRE(test::haveOsmesa());  // dev.sh installs libosmesa6-dev
  const fs::path out = fs::current_path() / "sdf_import_crazyflie.png";
  fs::remove(out);
  {
    Scene scene = typeScene(kCrazyflie, "ode", kCrazyflieDriver,
                            R"(<render engine="osmesa" background="1 1 1" width="320" height="240"><camera name="c" xyz="0.12 -0.12 1.1" look_at="0 0 1" snapshot=")" +
                                out.string() + R"("/></render>)",
                            "xyz=\"0 0 1\"");
    scene.environment->start();
    scene.environment->step(10);
    scene.environment->stop();
  }
  const Image im = test::readPng(out);
  REQUIRE(im.width == 320);
  // the mesh covers a good part of the middle of the picture (its bounding box would be a block)
  int drawn = 0, middle = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const std::uint8_t* px = im.pixel(x, y);
      if (px[0] < 230 || px[1] < 230 || px[2] < 230) {
        ++drawn;
        if (std::abs(x - 160) < 60 && std::abs(y - 120) < 60) ++middle;
      }
    }
  CHECK(middle > 1500);
  CHECK(drawn < im.width * im.height / 2);
}
