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

TEST_CASE("artifact files: a second root named as a node of the first is reported at its line, not thrown later",
          "[scene][artifact_reader]") {
  // (found by the artifact fuzzer: the loader let the artifact's own check throw past it)
  const fs::path dir = writeType("two_roots.xml", R"(<artifact>
  <physic name="body" mass="1">
    <box size="0.2 0.2 0.06"/>
    <physic name="arm_x"><box size="0.1 0.1 0.1"/></physic>
  </physic>
  <physic name="arm_x" mass="1"><box size="0.1 0.1 0.1"/></physic>
</artifact>
)");
  try {
    (void)loadSceneFromString(R"(<scene><type name="t" file="two_roots.xml"/>
      <swarm type="t" count="2" name="a{i}" layout="grid" spacing="1"/></scene>)",
                              "s.xml", dir, {});
    FAIL("loaded");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Contains("two_roots.xml:6: error: physic node 'arm_x': duplicate node name in this artifact"));
  }
}

TEST_CASE("artifact files: joints are read as written, what does not fit a joint is said at its line",
          "[scene][artifact_reader][joints]") {
  const fs::path dir = writeType("arm.xml", R"(<artifact>
  <physic name="base" static="true">
    <physic name="arm" joint="hinge" axis="0 2 0" lower="-1" upper="1.5" damping="0.01" max_torque="2" mass="1">
      <box size="0.1 0.1 0.5" xyz="0 0 -0.25"/>
      <physic name="slide" joint="slider" axis="1 0 0" max_force="5" xyz="0 0 -0.5">
        <sphere radius="0.05"/>
      </physic>
      <physic name="knob" joint="ball" xyz="0 0 -0.1"><sphere radius="0.02"/></physic>
    </physic>
  </physic>
</artifact>
)");
  Scene scene = loadSceneFromString(R"(<scene><type name="arm" file="arm.xml"/><artifact name="a" type="arm"/></scene>)",
                                    "s.xml", dir, {});
  const Artifact& a = *scene.environment->findArtifact("a");
  const JointSpec& arm = a.node("arm")->joint();
  CHECK(arm.kind == JointSpec::Kind::Hinge);
  CHECK(arm.axis == Vec3::UnitY());  // made unit
  CHECK(arm.lower == -1.0);
  CHECK(arm.upper == 1.5);
  CHECK(arm.damping == 0.01);
  CHECK(arm.max_effort == 2.0);
  CHECK(a.node("slide")->joint().kind == JointSpec::Kind::Slider);
  CHECK(a.node("slide")->joint().max_effort == 5.0);
  CHECK(a.node("knob")->joint().kind == JointSpec::Kind::Ball);
  CHECK(a.node("base")->joint().kind == JointSpec::Kind::Rigid);

  writeType("bad_joints.xml", R"(<artifact>
  <physic name="base" static="true">
    <physic name="a" joint="hinge" max_force="2"><sphere radius="0.1"/></physic>
    <physic name="b" joint="wheel"><sphere radius="0.1"/></physic>
    <physic name="c" joint="ball" lower="0"><sphere radius="0.1"/></physic>
    <physic name="d" joint="slider" axis="0 0 0"><sphere radius="0.1"/></physic>
    <physic name="e" axis="1 0 0"><sphere radius="0.1"/></physic>
  </physic>
</artifact>
)");
  try {
    (void)parseSceneString(R"(<scene><type name="b" file="bad_joints.xml"/><artifact name="x" type="b"/></scene>)", "s.xml",
                           dir, {});
    FAIL("parsed");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Contains("bad_joints.xml:3: error: <physic>: a hinge's motor takes max_torque, not max_force"));
    CHECK_THAT(e.what(), Contains("bad_joints.xml:4: error: <physic>: joint must be hinge, slider, ball or fixed, got 'wheel'"));
    CHECK_THAT(e.what(), Contains("bad_joints.xml:5: error: <physic>: 'lower' belongs to a hinge or slider joint, and this joint is a ball"));
    CHECK_THAT(e.what(), Contains("bad_joints.xml:6: error: <physic>: axis must be a non-zero vector"));
    CHECK_THAT(e.what(), Contains("bad_joints.xml:7: error: <physic>: 'axis' belongs to a hinge or slider joint (this node has no joint attribute)"));
  }
  // a limit beyond what a hinge can have: at the node, when the scene is built
  writeType("wide.xml", R"(<artifact>
  <physic name="base" static="true">
    <physic name="arm" joint="hinge" upper="4"><sphere radius="0.1"/></physic>
  </physic>
</artifact>
)");
  CHECK_THROWS_WITH(
      loadSceneFromString(R"(<scene><type name="w" file="wide.xml"/><artifact name="x" type="w"/></scene>)", "s.xml", dir, {}),
      Contains("wide.xml:3: error: physic node 'arm': a hinge's limits must lie within [-pi, pi] rad"));
}
