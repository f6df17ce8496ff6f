// Bodies (bodies.cpp): moving a body between steps, and the state hash over every body.
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

using namespace ssx;
using ssx::test::addBall;
using ssx::test::at;
using ssx::test::Counter;
using ssx::test::CountingSensor;
using ssx::test::LambdaDriver;
using ssx::test::ThrowingSensor;

TEST_CASE("setBodyState moves a body between steps, in the engine and the snapshot", "[environment]") {
  EnvironmentSettings s;
  s.physics.gravity = Vec3::Zero();
  Environment env(s);
  Artifact& a = addBall(env, "a");
  Artifact& b = addBall(env, "b", 2);
  CHECK_THROWS_WITH(env.setBodyState(0, {}), Catch::Contains("not running"));
  env.step();
  BodyState teleport;
  teleport.pose.position = Vec3(5, -3, 2);
  teleport.pose.orientation = Quat(Eigen::AngleAxisd(0.5, Vec3::UnitZ()));
  teleport.linear_velocity = Vec3(1, 0, 0);
  env.setBodyState(a.root().bodyIndex(), teleport);
  // the snapshot shows it at once; the engine continues from it
  CHECK(a.pose().position == teleport.pose.position);
  CHECK(b.pose().position == Vec3(2, 0, 1));
  env.step(100);
  CHECK(a.pose().position.x() == Approx(5 + 100 * toSeconds(s.timestep)).epsilon(1e-9));
  CHECK(a.pose().position.y() == Approx(-3));
  CHECK(a.pose().orientation.angularDistance(teleport.pose.orientation) < 1e-9);
  CHECK(b.pose().position == Vec3(2, 0, 1));

  BodyState wild = teleport;
  wild.linear_velocity = Vec3(1e9, 0, 0);
  CHECK_THROWS_WITH(env.setBodyState(a.root().bodyIndex(), wild), Catch::Contains("max_linear_speed"));
  wild.linear_velocity = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  CHECK_THROWS_WITH(env.setBodyState(a.root().bodyIndex(), wild), Catch::Contains("finite"));
  CHECK_THROWS_WITH(env.setBodyState(7, teleport), Catch::Contains("no body 7 (there are 2)"));
  CHECK(a.pose().position.x() == Approx(5.1).epsilon(1e-9));  // the refused calls changed nothing

  // from a plugin's step it would race the other threads: refused with the reason
  Environment env2;
  Artifact& c = addBall(env2, "c");
  c.setDriver(std::make_unique<LambdaDriver>([&env2](Driver&, const StepInfo&) { env2.setBodyState(0, {}); }));
  CHECK_THROWS_WITH(env2.step(), Catch::Contains("setBodyState is not allowed from a driver"));
}
