// Robots from URDF (scene/import): real descriptions written for Bullet and Gazebo (tests/data/robots)
// load on ODE and Bullet with the masses and inertias of their files, their joints move as closed
// forms say (a cart-pole's pole falls as the Lagrangian says, a door stops at its limits, an arm
// holds a commanded pose under gravity and falls without one), and what is wrong with a file is
// said at its line before anything runs.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

using namespace ssx;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

const fs::path kRobots = fs::path(SSX_EXAMPLES_DIR) / "robots";

// a scene of one robot of type `file`, placed as `placement` says
Scene robotScene(const fs::path& file, const std::string& engine, const std::string& extra = "",
                 const std::string& placement = "xyz=\"0 0 0\"") {
  const std::string xml = "<scene><environment timestep=\"0.001\" seed=\"1\"/><physics engine=\"" + engine +
                          "\"/><type name=\"robot\" file=\"" + fs::absolute(file).string() +
                          "\"/><artifact name=\"r\" type=\"robot\" " + placement + "/>" + extra + "</scene>";
  return loadSceneFromString(xml, "urdf_test.xml", fs::current_path(), test::testOptions());
}

// a copy of a test robot with some of its text replaced, in the test's own directory
fs::path variant(const fs::path& original, const std::string& name,
                 std::initializer_list<std::pair<std::string, std::string>> edits) {
  std::string text = test::fileText(original);
  for (const auto& [from, to] : edits) {
    const auto at = text.find(from);
    REQUIRE(at != std::string::npos);
    text.replace(at, from.size(), to);
  }
  const fs::path dir = fs::current_path() / "urdf_import_test";
  fs::create_directories(dir);
  // (the meshes are found relative to the copy: link them in)
  std::error_code ec;
  if (fs::exists(original.parent_path() / "meshes") && !fs::exists(dir / "meshes"))
    fs::create_directory_symlink(original.parent_path() / "meshes", dir / "meshes", ec);
  std::ofstream(dir / name) << text;
  return dir / name;
}

std::string errorsOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// the pole's tilt from upright about y (its z axis in the world's x-z plane)
double tilt(const PhysicNode& n) {
  const Vec3 up = n.pose().orientation * Vec3::UnitZ();
  return std::atan2(up.x(), up.z());
}

}  // namespace

TEST_CASE("A URDF cart-pole loads on both engines with its file's masses and inertias", "[import][urdf]") {
  for (const std::string engine : {"ode", "bullet"}) {
    CAPTURE(engine);
    Scene scene = robotScene(kRobots / "simple/cartpole.urdf", engine);
    const Artifact& a = *scene.environment->findArtifact("r");
    // the slide bar has mass 0: fixed in the world (PyBullet's convention); cart and pole move
    const PhysicNode& bar = *a.node("slideBar");
    CHECK(bar.isStatic());
    const PhysicNode& cart = *a.node("cart");
    const PhysicNode& pole = *a.node("pole");
    CHECK(cart.spec().joint.kind == JointSpec::Kind::Slider);
    CHECK(cart.spec().joint.lower == -15);
    CHECK(cart.spec().joint.upper == 15);
    CHECK(cart.spec().joint.max_effort == 1000);
    CHECK(cart.spec().joint.max_velocity == 5);
    CHECK(pole.spec().joint.kind == JointSpec::Kind::Hinge);
    CHECK(pole.spec().joint.axis == Vec3::UnitY());
    CHECK_FALSE(std::isfinite(pole.spec().joint.upper));  // continuous
    const MassProperties m = bodyMass(pole.spec());
    CHECK(m.mass == 10);
    CHECK(m.center_of_mass.isApprox(Vec3(0, 0, 0.5)));
    CHECK(m.inertia.isApprox(Mat3::Identity()));
    CHECK(bodyMass(cart.spec()).mass == 1);
  }
}

TEST_CASE("A URDF cart-pole's pole falls as the Lagrangian of the cart-pole says", "[import][urdf]") {
  // the pole's joint frame turned 0.1 rad about its axis: it starts tilted, at rest
  const fs::path file = variant(kRobots / "simple/cartpole.urdf", "tilted_cartpole.urdf",
                                {{R"(<origin xyz="0.0 0.0 0"/>
    <parent link="cart"/>)", R"(<origin xyz="0.0 0.0 0" rpy="0 0.1 0"/>
    <parent link="cart"/>)"}});
  // the closed form: cart M on a frictionless rail, pole m with its centre l above the pivot and
  // inertia I about it; RK4 on theta'' = ((M+m) m g l sin - m^2 l^2 sin cos theta'^2) / ((M+m)(I+m l^2) - m^2 l^2 cos^2)
  const double M = 1, m = 10, l = 0.5, I = 1, g = 9.81;
  auto accel = [&](double th, double w) {
    const double s = std::sin(th), c = std::cos(th);
    return ((M + m) * m * g * l * s - m * m * l * l * s * c * w * w) / ((M + m) * (I + m * l * l) - m * m * l * l * c * c);
  };
  double th = 0.1, w = 0;
  const double h = 1e-4;
  for (int i = 0; i < 6000; ++i) {  // 0.6 s
    const double k1 = w, l1 = accel(th, w);
    const double k2 = w + h / 2 * l1, l2 = accel(th + h / 2 * k1, w + h / 2 * l1);
    const double k3 = w + h / 2 * l2, l3 = accel(th + h / 2 * k2, w + h / 2 * l2);
    const double k4 = w + h * l3, l4 = accel(th + h * k3, w + h * l3);
    th += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    w += h / 6 * (l1 + 2 * l2 + 2 * l3 + l4);
  }
  for (const std::string engine : {"ode", "bullet"}) {
    CAPTURE(engine);
    Scene scene = robotScene(file, engine);
    Environment& env = *scene.environment;
    env.start();
    const PhysicNode& pole = *env.findArtifact("r")->node("pole");
    CHECK(tilt(pole) == Approx(0.1).margin(1e-9));
    for (int i = 0; i < 600; ++i) env.step();
    CAPTURE(th);
    // (from 0.1 rad the pole has fallen to about 1.1 rad: within 1 % of the closed form)
    CHECK(th > 0.8);
    CHECK(tilt(pole) == Approx(th).epsilon(0.01));
    // the cart moved the other way, as momentum along the rail is kept
    CHECK(env.findArtifact("r")->node("cart")->state().pose.position.x() < -0.05);
  }
}

TEST_CASE("A URDF door with limits stops at them, and without them turns on", "[import][urdf]") {
  const fs::path limited = variant(kRobots / "simple/door.urdf", "limited_door.urdf",
                                   {{R"(type="continuous">)", R"(type="revolute">)"},
                                    {R"(<axis xyz="0 0 1"/>)", R"(<axis xyz="0 0 1"/><limit lower="-0.5" upper="0.5" effort="0" velocity="2"/>)"}});
  for (const std::string engine : {"ode", "bullet"}) {
    for (const bool with_limits : {true, false}) {
      CAPTURE(engine, with_limits);
      Scene scene = robotScene(with_limits ? limited : kRobots / "simple/door.urdf", engine);
      Environment& env = *scene.environment;
      env.start();
      PhysicNode& door = *env.findArtifact("r")->node("childA");
      CHECK(env.findArtifact("r")->root().isStatic());  // joined to the link "world" by a fixed joint
      double most = 0;
      for (int i = 0; i < 3000; ++i) {
        door.addTorque(Vec3(0, 0, 4.0));  // pushed open for 3 s (against the joint's damping of 1 N m s)
        env.step();
        most = std::max(most, door.jointPosition());
      }
      if (with_limits) {
        CHECK(most < 0.5 + 0.02);
        CHECK(door.jointPosition() == Approx(0.5).margin(0.02));
      } else {
        CHECK(most > 2.0);  // (past it: the hinge's angle is read within [-pi, pi])
      }
    }
  }
}

TEST_CASE("The KUKA iiwa from URDF: meshes as hulls, joints that hold a commanded pose and fall without one",
          "[import][urdf][mesh]") {
  for (const std::string engine : {"ode", "bullet"}) {
    CAPTURE(engine);
    Scene scene = robotScene(kRobots / "kuka_iiwa/model.urdf", engine);
    Environment& env = *scene.environment;
    Artifact& a = *env.findArtifact("r");
    CHECK(a.root().isStatic());  // link 0 has mass 0: bolted to the world
    // masses as the file gives them (link 1: 4 kg, ... link 7: 0.3 kg)
    CHECK(bodyMass(a.node("lbr_iiwa_link_1")->spec()).mass == 4);
    CHECK(bodyMass(a.node("lbr_iiwa_link_7")->spec()).mass == Approx(0.3));
    // the collision meshes became convex hulls (each link's STL)
    const Shape& s = a.node("lbr_iiwa_link_3")->spec().shapes.at(0);
    REQUIRE(s.kind == Shape::Kind::Mesh);
    CHECK(s.mesh->hull_volume > 0);
    CHECK(s.mesh->hull_vertices.size() < s.mesh->vertices.size());
    env.start();
    // every joint held at 0.3 rad by its motor, under gravity, within 0.02 rad
    for (std::size_t i = 0; i < a.nodeCount(); ++i)
      if (a.nodeAt(i).spec().joint.hasPosition()) a.nodeAt(i).setJointPosition(0.3);
    for (int i = 0; i < 2000; ++i) env.step();
    double worst = 0;
    for (std::size_t i = 0; i < a.nodeCount(); ++i)
      if (a.nodeAt(i).spec().joint.hasPosition()) worst = std::max(worst, std::abs(a.nodeAt(i).jointPosition() - 0.3));
    CHECK(worst < 0.02);  // (the servo's error under the arm's weight, 2 s after the command)
  }
  // without control, on a base tilted 0.3 rad about y, the arm falls about joint 2 (its axis along y)
  Scene scene = robotScene(kRobots / "kuka_iiwa/model.urdf", "ode", "", "rpy=\"0 0.3 0\"");
  Environment& env = *scene.environment;
  env.start();
  const PhysicNode& j2 = *env.findArtifact("r")->node("lbr_iiwa_link_2");
  for (int i = 0; i < 1000; ++i) env.step();
  CHECK(std::abs(j2.jointPosition()) > 0.3);
}

TEST_CASE("The Husky from URDF: roslaunch's $(optenv) read, a massless base_footprint carries its body, it rests on its wheels",
          "[import][urdf]") {
  for (const std::string engine : {"ode", "bullet"}) {
    CAPTURE(engine);
    Scene scene = robotScene(kRobots / "husky/husky.urdf", engine, "<ground/>", "xyz=\"0 0 0.1\"");
    Environment& env = *scene.environment;
    const Artifact& husky = *env.findArtifact("r");
    CHECK_FALSE(husky.root().isStatic());
    // the IMU's pose came from $(optenv HUSKY_IMU_XYZ 0.19 0 0.149)'s default
    CHECK(husky.node("imu_link")->spec().pose.position.isApprox(Vec3(0.19, 0, 0.149), 1e-12));
    env.start();
    env.step(1500);
    // on its four wheels (radius 0.17775 m, their axles 0.03282 m above base_link, base_link 0.14493 m above
    // base_footprint): base_footprint at the ground, level
    const Pose p = husky.root().pose();
    CHECK(std::abs(p.position.z()) < 0.01);
    CHECK((p.orientation * Vec3::UnitZ()).z() > 0.999);
  }
}

// the Husky with motors on its four wheels (its URDF gives them none: <joint> in the scene's <type>),
// skid-steered by diff_drive's full model, both sides' wheels driven alike
Scene drivenHusky(const std::string& engine, const std::string& joint_extra = "") {
  std::string joints;
  for (const char* wheel : {"front_left", "rear_left", "front_right", "rear_right"})
    joints += std::string("<joint node=\"") + wheel + "_wheel_link\" max_torque=\"60\"" + joint_extra + "/>";
  const std::string xml =
      "<scene><environment timestep=\"0.001\" seed=\"1\"/><physics engine=\"" + engine +
      "\"/><type name=\"husky\" file=\"" + fs::absolute(kRobots / "husky/husky.urdf").string() + "\">" + joints +
      "<driver plugin=\"diff_drive\" model=\"full\" wheel_radius=\"0.17775\" axle_length=\"0.5708\" "
      "max_wheel_speed=\"10\" left_wheel=\"front_left_wheel_link rear_left_wheel_link\" "
      "right_wheel=\"front_right_wheel_link rear_right_wheel_link\"/></type>"
      "<ground/><artifact name=\"r\" type=\"husky\" xyz=\"0 0 0.02\"/></scene>";
  return loadSceneFromString(xml, "husky_test.xml", fs::current_path(), test::testOptions());
}

double yawOf(const Quat& q) {
  return std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()));
}

TEST_CASE("The Husky from URDF drives a commanded twist: its wheels given motors in the scene, skid-steered by "
          "diff_drive",
          "[import][urdf]") {
  for (const std::string engine : {"ode", "bullet"}) {
    CAPTURE(engine);
    Scene scene = drivenHusky(engine);
    Environment& env = *scene.environment;
    Artifact& husky = *env.findArtifact("r");
    auto* driver = dynamic_cast<CommandInterface*>(husky.driver());
    REQUIRE(driver != nullptr);
    // the settings reached the joints: the wheels have motors, the other joints none
    CHECK(husky.node("rear_right_wheel_link")->joint().max_effort == 60.0);
    env.start();
    env.step(500);  // settled on its wheels
    const Pose start = husky.root().pose();
    // 0.5 m/s ahead for 4 s
    driver->setCommand(Command::velocityYawRate(Vec3(0.5, 0, 0), 0));
    env.step(4000);
    const Pose ahead = husky.root().pose();
    const Vec3 moved = ahead.position - start.position;
    CAPTURE(moved.transpose());
    CHECK(moved.x() > 0.5 * 4 * 0.9);
    CHECK(moved.x() < 0.5 * 4 * 1.05);
    CHECK(std::abs(moved.y()) < 0.05);
    CHECK(std::abs(yawOf(ahead.orientation) - yawOf(start.orientation)) < 0.05);
    // turning on the spot at 0.5 rad/s for 2 s: a skid-steered robot's wheels slip sideways, so it
    // turns slower than wheels on an axle of 0.5708 m would, but it turns left and stays about where
    // it was (it turns about a point near its centre of mass, 8.7 cm behind base_link, slipping)
    // (the first half second stops it from 0.5 m/s)
    driver->setCommand(Command::velocityYawRate(Vec3::Zero(), 0.5));
    env.step(500);
    const Pose stopped = husky.root().pose();
    env.step(2000);
    const Pose turned = husky.root().pose();
    const double yaw = yawOf(turned.orientation) - yawOf(stopped.orientation);
    const double drift = (turned.position - stopped.position).norm();
    CAPTURE(yaw, drift);
    CHECK(yaw > 0.3);
    CHECK(yaw < 1.0 + 0.05);
    CHECK(drift < 0.15);
    CHECK((turned.orientation * Vec3::UnitZ()).z() > 0.99);
    WARN(engine << ": ahead " << moved.x() << " m in 4 s, turned " << yaw << " rad in 2 s, drifting " << drift << " m");
  }
}

TEST_CASE("A <type>'s <joint> settings: a node the file lacks, or a setting that is not a joint's, said at its line",
          "[import][urdf]") {
  const std::string base = "<scene><environment timestep=\"0.001\"/><type name=\"husky\" file=\"" +
                           fs::absolute(kRobots / "husky/husky.urdf").string() + "\">\n";
  const auto load = [&](const std::string& joint) {
    return errorsOf([&] {
      loadSceneFromString(base + joint + "\n</type><artifact name=\"r\" type=\"husky\"/></scene>", "joints.xml",
                          fs::current_path(), test::testOptions());
    });
  };
  CHECK_THAT(load(R"(<joint node="front_left_wheel" max_torque="5"/>)"),
             Contains("joints.xml:2: error: <joint>: the type's file has no physic node 'front_left_wheel' (did you "
                      "mean 'front_left_wheel_link'?)"));
  CHECK_THAT(load(R"(<joint node="front_left_wheel_link" mass="5"/>)"),
             Contains("joints.xml:2: error: <joint>: 'mass' is not a joint setting"));
  CHECK_THAT(load(R"(<joint node="front_left_wheel_link" max_torque="lots"/>)"), Contains("joints.xml:2: error:"));
  // a setting the joint does not take is the artifact reader's error, at the scene's line
  CHECK_THAT(load(R"(<joint node="front_left_wheel_link" max_force="5"/>)"),
             Contains("a hinge's motor takes max_torque, not max_force"));
  CHECK(load(R"(<joint node="front_left_wheel_link" max_torque="5"/>)").empty());
}

TEST_CASE("A URDF's problems are said at their lines before anything runs", "[import][urdf]") {
  const fs::path cartpole = kRobots / "simple/cartpole.urdf";
  SECTION("a floating joint is refused with what to do") {
    const fs::path f = variant(cartpole, "floating.urdf", {{R"(type="prismatic")", R"(type="floating")"}});
    const std::string e = errorsOf([&] { robotScene(f, "ode"); });
    CHECK_THAT(e, Contains("floating.urdf:42: error: joint 'slider_to_cart': floating joints are not simulated"));
  }
  SECTION("a missing mesh") {
    const fs::path f = variant(cartpole, "nomesh.urdf", {{R"(<box size="0.5 0.5 0.2"/>
      </geometry>
      <origin xyz="0 0 0"/>
      <material name="blue">)", R"(<mesh filename="meshes/none.stl"/>
      </geometry>
      <origin xyz="0 0 0"/>
      <material name="blue">)"}});
    const std::string e = errorsOf([&] { robotScene(f, "ode"); });
    CHECK_THAT(e, Contains("nomesh.urdf:21: error: link 'cart': mesh 'meshes/none.stl': no file"));
  }
  SECTION("xacro left in the file: said, with what to run") {
    const fs::path f = variant(cartpole, "xacro.urdf", {{R"(<mass value="10"/>)", R"(<mass value="${cart_mass}"/>)"}});
    CHECK_THAT(errorsOf([&] { robotScene(f, "ode"); }),
               Contains("xacro.urdf:62: error: '${cart_mass}': this is a xacro file, not a URDF: run `xacro xacro.urdf"));
    const fs::path g = variant(cartpole, "arg.urdf", {{R"(<mass value="10"/>)", R"x(<mass value="$(arg m)"/>)x"}});
    CHECK_THAT(errorsOf([&] { robotScene(g, "ode"); }), Contains("arg.urdf:62: error: '$(arg m)': only roslaunch's"));
    const fs::path h = variant(cartpole, "env.urdf", {{R"(<mass value="10"/>)", R"x(<mass value="$(env SSX_TEST_UNSET_MASS)"/>)x"}});
    CHECK_THAT(errorsOf([&] { robotScene(h, "ode"); }),
               Contains("env.urdf:62: error: '$(env SSX_TEST_UNSET_MASS)': the environment variable SSX_TEST_UNSET_MASS is not set"));
  }
  SECTION("a loop and an unknown link") {
    const fs::path f = variant(cartpole, "loop.urdf", {{R"(<parent link="slideBar"/>)", R"(<parent link="pole"/>)"}});
    const std::string e = errorsOf([&] { robotScene(f, "ode"); });
    CHECK_THAT(e, Contains("loop.urdf:") && Contains("the joints make a loop"));
    const fs::path g = variant(cartpole, "unknown_link.urdf", {{R"(<child link="pole"/>)", R"(<child link="pol"/>)"}});
    CHECK_THAT(errorsOf([&] { robotScene(g, "ode"); }), Contains("unknown_link.urdf:73: error: joint 'cart_to_pole': no link named 'pol'"));
  }
  SECTION("a value urdfdom cannot read, and a file that is not XML") {
    const fs::path f = variant(cartpole, "bad_value.urdf", {{R"(<mass value="10"/>)", R"(<mass value="ten"/>)"}});
    CHECK_THAT(errorsOf([&] { robotScene(f, "ode"); }), Contains("bad_value.urdf:62: error: <mass>: value 'ten' is not a number"));
    const fs::path g = variant(cartpole, "not_xml.urdf", {{R"(<link name="cart">)", R"(<link name="cart" <)"}});
    CHECK_THAT(errorsOf([&] { robotScene(g, "ode"); }), Contains("not_xml.urdf:"));
  }
  SECTION("what ssx does not read is listed: Gazebo extensions, transmissions, unknown elements") {
    const fs::path f = variant(cartpole, "gazebo.urdf", {{R"(</robot>)", R"(<gazebo reference="cart"><mu1>0.2</mu1></gazebo>
<transmission name="t1"/><wheel/></robot>)"}});
    Scene scene = robotScene(f, "ode");
    std::string all;
    for (const auto& w : scene.warnings) all += w.str() + "\n";
    CHECK_THAT(all, Contains("gazebo.urdf:80: warning: <gazebo reference=\"cart\">: Gazebo's extension is not read"));
    CHECK_THAT(all, Contains("gazebo.urdf:81: warning: <transmission name=\"t1\">"));
    CHECK_THAT(all, Contains("gazebo.urdf:81: warning: unknown element <wheel> in <robot>"));
  }
}

TEST_CASE("ssx import prints a URDF as an artifact file that loads as the same robot", "[import][urdf]") {
  const fs::path dir = fs::current_path() / "urdf_import_out";
  fs::create_directories(dir);
  const ImportedRobot robot = importRobotDescription(kRobots / "kuka_iiwa/model.urdf", dir);
  CHECK(robot.bodies == 8);  // link 0 (static) and links 1-7
  CHECK(robot.joints == 7);
  CHECK_THAT(robot.artifact_xml, Contains("<physic name=\"lbr_iiwa_link_1\""));
  CHECK_THAT(robot.artifact_xml, Contains("joint=\"hinge\""));
  std::ofstream(dir / "iiwa.xml") << robot.artifact_xml;
  // the printed file, read as any artifact file, is the same tree with the same masses
  Scene from_urdf = robotScene(kRobots / "kuka_iiwa/model.urdf", "ode");
  Scene from_xml = robotScene(dir / "iiwa.xml", "ode");
  const Artifact& a = *from_urdf.environment->findArtifact("r");
  const Artifact& b = *from_xml.environment->findArtifact("r");
  REQUIRE(a.nodeCount() == b.nodeCount());
  for (std::size_t i = 0; i < a.nodeCount(); ++i) {
    CAPTURE(a.nodeAt(i).name());
    CHECK(a.nodeAt(i).name() == b.nodeAt(i).name());
    const MassProperties ma = bodyMass(a.nodeAt(i).spec()), mb = bodyMass(b.nodeAt(i).spec());
    CHECK(ma.mass == mb.mass);
    CHECK((ma.inertia - mb.inertia).norm() <= 1e-12 * (1 + ma.inertia.norm()));
    CHECK(a.nodeAt(i).pose().position.isApprox(b.nodeAt(i).pose().position, 1e-12));
  }
}
