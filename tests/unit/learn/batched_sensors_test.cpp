// One kind of sensor of every robot of every copy in one array (batched_sensors.cpp,
// VectorEnvironment::readSensors): each row holds what that robot's own sensor (or driver)
// reads, in the documented layout; empty slots are zeros; what a robot lacks, a kind that does
// not exist and an array of the wrong size are refused, naming the robot and what to add.
#include "scene_util.hpp"
#include "test_util.hpp"

#include <ssx/ssx.hpp>
#include <ssx/vector_environment.hpp>

#include <catch2/catch.hpp>

#include <string>
#include <vector>

using namespace ssx;
using Catch::Contains;
using ssx::test::kArtifacts;

namespace {

// three e-pucks in a row, 10 cm apart (their proximity sensors see each other), turning slowly
Scene epucks(std::size_t copy) {
  SceneOptions options;
  options.threads = 1;
  options.seed = 10 + copy;
  return loadSceneFromString(
      "<scene><environment timestep=\"0.002\"/><type name=\"e\" file=\"" + (kArtifacts / "epuck_full.xml").string() +
          "\"/><ground/><swarm type=\"e\" count=\"3\" name=\"e{i}\" spacing=\"0.1\" xyz=\"0 0 0\">"
          "</swarm></scene>",
      "e.xml", kArtifacts, options);
}

template <class M>
const M& latest(const Artifact& a) {
  for (std::size_t k = 0; k < a.sensorCount(); ++k)
    if (const auto* m = dynamic_cast<const M*>(&a.sensor(k).latest())) return *m;
  FAIL("no such sensor");
  throw;
}

}  // namespace

TEST_CASE("batched sensors: every robot's own reading, in the documented layout", "[learn]") {
  VectorEnvironment v(epucks, 2, 2);
  const std::vector<double> wheels{1.0, 2.0, 1.5, 1.0, 0.5, 1.0};  // per robot: left, right (rad/s), copy 0
  std::vector<double> both(wheels);
  both.insert(both.end(), wheels.begin(), wheels.end());
  v.setCommands(CommandLevel::Wheels, both, 2);
  v.step(200);
  const std::size_t robots = 3;

  const std::size_t rays = v.sensorWidth("proximity");
  CHECK(rays == 8);
  std::vector<double> proximity(2 * robots * rays);
  v.readSensors("proximity", proximity);
  double seen = 0;
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t r = 0; r < robots; ++r) {
      const auto& m = latest<ProximityMeasurement>(*v[i].findArtifact("e" + std::to_string(r)));
      for (std::size_t k = 0; k < rays; ++k) CHECK(proximity[(i * robots + r) * rays + k] == m.readings[k]);
      for (const double x : m.readings) seen += x;
    }
  CHECK(seen > 0);  // neighbours 10 cm apart are within the rays' 5 cm beyond the body

  // range and bearing: every e-puck hears the two others; a third slot stays empty
  REQUIRE(v.sensorWidth("range_and_bearing", 3) == 12);
  std::vector<double> rab(2 * robots * 12);
  v.readSensors("range_and_bearing", rab, 3);
  for (std::size_t row = 0; row < 2 * robots; ++row) {
    const auto& m = latest<RangeBearingMeasurement>(*v[row / robots].findArtifact("e" + std::to_string(row % robots)));
    REQUIRE(m.messages.size() == 2);
    for (std::size_t k = 0; k < 2; ++k) {
      CHECK(rab[row * 12 + 4 * k] == 1.0);
      CHECK(rab[row * 12 + 4 * k + 1] == m.messages[k].range);
      CHECK(rab[row * 12 + 4 * k + 2] == m.messages[k].bearing);
      CHECK(rab[row * 12 + 4 * k + 3] == m.messages[k].elevation);
    }
    for (std::size_t k = 8; k < 12; ++k) CHECK(rab[row * 12 + k] == 0.0);
  }

  std::vector<double> ground(2 * robots * v.sensorWidth("ground"));
  v.readSensors("ground", ground);
  CHECK(ground[4] == latest<GroundMeasurement>(*v[1].findArtifact("e1")).readings[0]);

  REQUIRE(v.sensorWidth("odometry") == 9);
  std::vector<double> odometry(2 * robots * 9);
  v.readSensors("odometry", odometry);
  const Odometry o = dynamic_cast<const OdometryInterface*>(v[1].findArtifact("e2")->driver())->odometry();
  const double expected[9] = {o.x,          o.y,           o.yaw,        o.forward,    o.yaw_rate,
                              o.left_speed, o.right_speed, o.left_angle, o.right_angle};
  for (std::size_t k = 0; k < 9; ++k) CHECK(odometry[5 * 9 + k] == expected[k]);
  CHECK(odometry[5 * 9 + 2] != 0.0);  // e2 turned: its wheels differ

  // what the e-pucks lack, kinds that do not exist, arrays of the wrong size
  CHECK_THROWS_WITH(v.sensorWidth("pose"), Contains("robot 'e0' has no pose to read: add <sensor plugin=\"pose\"/>"));
  CHECK_THROWS_WITH(v.sensorWidth("lidar"), Contains("no sensor kind 'lidar'"));
  CHECK_THROWS_WITH(v.readSensors("ground", std::span<double>(ground).first(2)), Contains("needs 2 x 3 x 1 numbers"));
}

TEST_CASE("batched sensors: motion capture and the range sensor of flying robots", "[learn]") {
  auto load = [](std::size_t) {
    SceneOptions options;
    options.threads = 1;
    return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"2\"/><type name=\"cf\" file=\"" +
                                   (kArtifacts / "crazyflie.xml").string() +
                                   "\"/><ground/><swarm type=\"cf\" count=\"2\" name=\"cf{i}\" spacing=\"1\" "
                                   "xyz=\"0 0 0.05\"><driver offset=\"0 0 1\"/></swarm></scene>",
                               "cf.xml", kArtifacts, options);
  };
  VectorEnvironment v(load, 2, 1);
  v.step(300);
  std::vector<double> pose(2 * 2 * 13);
  v.readSensors("pose", pose);
  const auto& m = latest<PoseMeasurement>(*v[1].findArtifact("cf1"));
  const Quat& q = m.pose.orientation;
  const double expected[13] = {m.pose.position.x(),
                               m.pose.position.y(),
                               m.pose.position.z(),
                               q.w(),
                               q.x(),
                               q.y(),
                               q.z(),
                               m.linear_velocity.x(),
                               m.linear_velocity.y(),
                               m.linear_velocity.z(),
                               m.angular_velocity.x(),
                               m.angular_velocity.y(),
                               m.angular_velocity.z()};
  for (std::size_t k = 0; k < 13; ++k) CHECK(pose[3 * 13 + k] == expected[k]);
  CHECK(pose[3 * 13 + 2] > 0.3);  // taking off
  // a Crazyflie carries no range sensor: refused, naming what to add
  CHECK_THROWS_WITH(v.sensorWidth("range", 2), Contains("add <sensor plugin=\"range\"/>"));
  CHECK_THROWS_WITH(v.sensorWidth("odometry"), Contains("its driver keeps no odometry"));
}

TEST_CASE("batched contacts: each robot's impulse from the ground and from other bodies", "[learn]") {
  VectorEnvironment v(epucks, 2, 2);
  std::vector<double> impulses(2 * 3 * 2);
  CHECK_THROWS_WITH(v.contactImpulses(impulses), Contains("call recordContacts(true)"));
  v.recordContacts();
  // in copy 1, e0 drives into e1 backing into it; e2 and copy 0 stand still
  std::vector<double> wheels(2 * 3 * 2, 0.0);
  wheels[6] = wheels[7] = 6.0;
  wheels[8] = wheels[9] = -6.0;
  v.setCommands(CommandLevel::Wheels, wheels, 2);
  v.step(250);
  v.contactImpulses(impulses);
  for (std::size_t row = 0; row < 6; ++row) CHECK(impulses[2 * row] > 0.0);  // all stand on the ground
  CHECK(impulses[2 * 3 + 1] > 0.0);                                          // copy 1: e0 and e1 pushed into each other
  CHECK(impulses[2 * 4 + 1] > 0.0);
  CHECK(impulses[2 * 4 + 1] == impulses[2 * 3 + 1]);
  CHECK(impulses[2 * 5 + 1] == 0.0);                                              // e2 touches nobody
  for (std::size_t row = 0; row < 3; ++row) CHECK(impulses[2 * row + 1] == 0.0);  // copy 0 stood still
  // the pair is in copy 1's list, the robots named through their bodies
  bool pair = false;
  for (const EngineContact& c : v[1].contacts())
    pair |= c.body_b >= 0 && v.robotOfBody()[static_cast<std::size_t>(c.body_a)] == 0 &&
            v.robotOfBody()[static_cast<std::size_t>(c.body_b)] == 1;
  CHECK(pair);
  CHECK_THROWS_WITH(v.contactImpulses(std::span<double>(impulses).first(3)), Contains("x 2 numbers"));
}
