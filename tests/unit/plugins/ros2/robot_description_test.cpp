// A robot's description for ROS tools, written from the artifact: urdfdom (what RViz and
// robot_state_publisher read it with) reads it back with the artifact's links, joints, limits and
// visuals, the root named base_link as /tf names it.
#include "../../../../plugins/ros2/robot_description.hpp"

#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <urdf_parser/urdf_parser.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>

using namespace ssx;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

Scene sceneOf(const std::string& type_file) {
  const std::string xml = "<scene><environment timestep=\"0.002\"/><type name=\"t\" file=\"" + type_file +
                          "\"/><ground/><artifact name=\"r\" type=\"t\"/></scene>";
  return loadSceneFromString(xml, "description.xml", fs::current_path(), test::testOptions());
}

}  // namespace

TEST_CASE("robot description: an ssx artifact's URDF has its nodes as links and its joints, read back by urdfdom",
          "[ros2][description]") {
  Scene scene = sceneOf(std::string(SSX_EXAMPLES_DIR) + "/artifacts/turtlebot3_burger.xml");
  const std::string text = ros2::robotDescription(*scene.environment->findArtifact("r"));
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text);
  REQUIRE(model != nullptr);
  CHECK(model->getName() == "r");
  CHECK(model->getRoot()->name == "base_link");
  for (const char* link : {"base_link", "left_wheel", "right_wheel", "caster", "deck"}) {
    CAPTURE(link);
    CHECK(model->getLink(link) != nullptr);
  }
  // the wheels turn without limits on hinges about their z axes, 0.08 m to either side
  const urdf::JointConstSharedPtr left = model->getJoint("left_wheel_joint");
  REQUIRE(left != nullptr);
  CHECK(left->type == urdf::Joint::CONTINUOUS);
  CHECK(left->parent_link_name == "base_link");
  CHECK(left->axis.z == Approx(1.0));
  const urdf::Pose& at = left->parent_to_joint_origin_transform;
  CHECK(at.position.y == Approx(0.08));
  CHECK(at.position.z == Approx(0.033));
  double roll = 0, pitch = 0, yaw = 0;
  at.rotation.getRPY(roll, pitch, yaw);
  CHECK(roll == Approx(-M_PI / 2));
  // the caster on a ball joint: floating (URDF has no ball); the deck fixed where the file puts it
  CHECK(model->getJoint("caster_joint")->type == urdf::Joint::FLOATING);
  const urdf::JointConstSharedPtr deck = model->getJoint("deck_joint");
  CHECK(deck->type == urdf::Joint::FIXED);
  CHECK(deck->parent_to_joint_origin_transform.position.x == Approx(-0.032));
  CHECK(deck->parent_to_joint_origin_transform.position.z == Approx(0.21));
  // each wheel drawn as its cylinder
  const urdf::LinkConstSharedPtr wheel = model->getLink("right_wheel");
  REQUIRE(wheel->visual != nullptr);
  REQUIRE(wheel->visual->geometry->type == urdf::Geometry::CYLINDER);
  const auto& cylinder = static_cast<const urdf::Cylinder&>(*wheel->visual->geometry);
  CHECK(cylinder.radius == Approx(0.033));
  CHECK(cylinder.length == Approx(0.018));
  CHECK(model->getLink("base_link")->visual_array.size() >= 1);
}

TEST_CASE("robot description: a URDF robot's joints keep their limits, its meshes their files and scales",
          "[ros2][description]") {
  Scene scene = sceneOf(std::string(SSX_EXAMPLES_DIR) + "/robots/kuka_iiwa/model.urdf");
  const std::string text = ros2::robotDescription(*scene.environment->findArtifact("r"));
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text);
  REQUIRE(model != nullptr);
  // the base bolted to the world is the root; its seven links hang from it on revolute joints
  CHECK(model->getRoot()->name == "base_link");
  const urdf::JointConstSharedPtr j2 = model->getJoint("lbr_iiwa_link_2_joint");
  REQUIRE(j2 != nullptr);
  CHECK(j2->type == urdf::Joint::REVOLUTE);
  CHECK(j2->limits->lower == Approx(-2.09439510239));
  CHECK(j2->limits->upper == Approx(2.09439510239));
  CHECK(j2->limits->effort == Approx(300));
  CHECK(j2->limits->velocity == Approx(10));
  const urdf::LinkConstSharedPtr link = model->getLink("lbr_iiwa_link_3");
  REQUIRE(link != nullptr);
  REQUIRE(link->visual != nullptr);
  REQUIRE(link->visual->geometry->type == urdf::Geometry::MESH);
  const auto& mesh = static_cast<const urdf::Mesh&>(*link->visual->geometry);
  CHECK_THAT(mesh.filename, Contains("file:///"));
  CHECK(fs::exists(mesh.filename.substr(std::string("file://").size())));
  CHECK(mesh.scale.x == Approx(1.0));
  std::size_t joints = 0;
  for (const auto& [name, joint] : model->joints_) joints += joint->type == urdf::Joint::REVOLUTE;
  CHECK(joints == 7);
}
