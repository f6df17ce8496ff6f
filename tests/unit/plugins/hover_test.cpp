// The hover driver: a PD on a rigid body holds the set-point it is given, or where the body started
// plus an offset, and the heading it is given, reading the body's pose sensor when it has one.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace ssx;
namespace fs = std::filesystem;

namespace {

Scene hoverScene(const std::string& driver_attributes) {
  return loadSceneFromString(R"(<scene><environment timestep="0.002" seed="3"/>
    <type name="body" file="hover_body.xml"/>
    <artifact name="b" type="body" xyz="1 -1 0.5"><driver )" + driver_attributes + R"(/></artifact></scene>)",
                             "hover.xml", test::kArtifacts);
}

double yawOf(const Quat& q) { return std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z())); }

}  // namespace

TEST_CASE("hover: holds the start plus the offset, within the pose sensor's noise", "[hover]") {
  Scene scene = hoverScene(R"(offset="0 0 1")");
  Environment& env = *scene.environment;
  env.step(2500);  // 5 s: twenty time constants of the critically damped 4 rad/s loop
  const Vec3 p = env.findArtifact("b")->pose().position;
  CHECK((p - Vec3(1, -1, 1.5)).norm() < 0.01);  // the pose sensor's noise is 2 mm
}

TEST_CASE("hover: a given target wins over the offset, and the yaw is held", "[hover]") {
  Scene scene = hoverScene(R"(target="-2 3 2" offset="0 0 5" yaw="1.2")");
  Environment& env = *scene.environment;
  env.step(2500);
  const Pose p = env.findArtifact("b")->pose();
  CHECK((p.position - Vec3(-2, 3, 2)).norm() < 0.01);
  CHECK(yawOf(p.orientation) == Approx(1.2).margin(0.01));
  // level: the heading is about z only
  CHECK((p.orientation * Vec3::UnitZ()).z() > 0.9999);
}

TEST_CASE("hover: a body without a dynamic root is refused while loading, where the driver is declared", "[hover]") {
  const fs::path dir = fs::current_path() / "hover_static";
  fs::create_directories(dir);
  std::ofstream(dir / "post.xml") << R"(<artifact>
  <physic name="post" static="true"><box size="0.1 0.1 1"/></physic>
  <driver plugin="hover"/>
</artifact>
)";
  CHECK_THROWS_WITH(loadSceneFromString(R"(<scene><type name="post" file="post.xml"/><artifact name="p" type="post"/></scene>)",
                                        "h.xml", dir),
                    Catch::Contains("post.xml:3: error:") && Catch::Contains("hover needs a dynamic physic root"));
}
