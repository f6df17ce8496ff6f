// Artifact files: the physic tree with its shapes, masses and poses, the render tree, and the
// plugins the type declares, read into the scene model as written; what is wrong is said at its line.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <numbers>

using namespace ssx;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

fs::path writeType(const std::string& name, const std::string& xml) {
  const fs::path dir = fs::current_path() / "artifact_reader";
  fs::create_directories(dir);
  std::ofstream(dir / name) << xml;
  return dir;
}

const char* kRobot = R"(<artifact>
  <physic name="base" mass="2" inertia="0.1 0.2 0.3" inertia_products="0.01 0 0" com="0 0 0.05">
    <box size="0.4 0.2 0.1"/>
    <physic name="mast" xyz="0 0 0.3" rpy="0 0 1.5707963267948966">
      <cylinder radius="0.02" length="0.5" density="800"/>
      <sphere radius="0.05" xyz="0 0 0.25"/>
    </physic>
  </physic>
  <render follow="base" name="shell" color="1 0 0">
    <box size="0.4 0.2 0.1"/>
    <render name="light" xyz="0 0 0.6"><sphere radius="0.03" color="1 1 0"/></render>
  </render>
  <sensor plugin="pose" period="2" position_noise="0.01"/>
  <sensor plugin="clock" class="clock"/>
  <driver plugin="hover" kp="9"/>
</artifact>
)";

}  // namespace

TEST_CASE("artifact files: node trees, shapes and plugin declarations are read as written", "[scene][artifact_reader]") {
  const fs::path dir = writeType("robot.xml", kRobot);
  const SceneModel model =
      parseSceneString(R"(<scene><type name="robot" file="robot.xml"/><artifact name="r" type="robot"/></scene>)",
                       "s.xml", dir, {});
  REQUIRE(model.types.size() == 1);
  const ArtifactTypeModel& t = model.types.at("robot");
  CHECK(t.name == "robot");
  REQUIRE(t.physic.size() == 1);
  const PhysicNodeSpec& base = *t.physic[0];
  CHECK(base.name == "base");
  CHECK(base.mass == 2.0);
  REQUIRE(base.inertia.has_value());
  CHECK((*base.inertia)(0, 0) == 0.1);
  CHECK((*base.inertia)(2, 2) == 0.3);
  CHECK((*base.inertia)(0, 1) == 0.01);
  CHECK((*base.inertia)(1, 0) == 0.01);
  CHECK(base.center_of_mass == Vec3(0, 0, 0.05));
  REQUIRE(base.shapes.size() == 1);
  CHECK(base.shapes[0].size == Vec3(0.4, 0.2, 0.1));
  REQUIRE(base.children.size() == 1);
  const PhysicNodeSpec& mast = base.children[0];
  CHECK(mast.name == "mast");
  CHECK(mast.pose.position == Vec3(0, 0, 0.3));
  CHECK((mast.pose.orientation * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-12));
  REQUIRE(mast.shapes.size() == 2);
  CHECK(mast.shapes[0].density == 800);
  CHECK(mast.shapes[1].pose.position == Vec3(0, 0, 0.25));

  REQUIRE(t.render.size() == 1);
  const RenderNodeSpec& shell = *t.render[0];
  CHECK(shell.follow == "base");
  CHECK(shell.name == "shell");
  REQUIRE(shell.children.size() == 2);
  CHECK(shell.children[0].primitive == RenderNodeSpec::Primitive::Box);
  CHECK(shell.children[1].name == "light");
  REQUIRE(shell.children[1].children.size() == 1);
  CHECK(shell.children[1].children[0].primitive == RenderNodeSpec::Primitive::Sphere);
  CHECK(shell.children[1].children[0].color[2] == 0.0f);

  REQUIRE(t.driver.has_value());
  CHECK(t.driver->plugin == "hover");
  CHECK(t.driver->params.get<double>("kp") == 9);
  REQUIRE(t.sensors.size() == 2);
  CHECK(t.sensors[0].plugin == "pose");
  CHECK(t.sensors[0].period == 2);
  CHECK(t.sensors[0].period_from.line == 13);
  CHECK_FALSE(t.sensors[0].params.has("period"));  // the loader's own attributes are no parameters
  CHECK(t.sensors[1].class_name == "clock");
  CHECK_FALSE(t.sensors[1].params.has("class"));
}

TEST_CASE("artifact files: each wrong shape or root is reported at its own line", "[scene][artifact_reader]") {
  const fs::path dir = writeType("bad.xml", R"(<artifact>
  <physic name="b">
    <box/>
    <box size="1 0 1"/>
    <capsule radius="0.1" length="-1"/>
    <sphere radius="-2"/>
  </physic>
</artifact>
)");
  writeType("wrong_root.xml", "<robot/>\n");
  try {
    (void)parseSceneString(R"(<scene><type name="b" file="bad.xml"/><type name="w" file="wrong_root.xml"/>
      <artifact name="x" type="b"/><artifact name="y" type="w"/></scene>)",
                           "s.xml", dir, {});
    FAIL("parsed");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Contains("bad.xml:3: error: <box>: missing attribute 'size'"));
    CHECK_THAT(e.what(), Contains("bad.xml:4: error: <box>: every size must be positive"));
    CHECK_THAT(e.what(), Contains("bad.xml:5: error: <capsule>: length must not be negative"));
    CHECK_THAT(e.what(), Contains("bad.xml:6: error:") && Contains("radius"));
    CHECK_THAT(e.what(), Contains("wrong_root.xml:1: error: the root element of an artifact file must be <artifact>, got <robot>"));
  }
}
