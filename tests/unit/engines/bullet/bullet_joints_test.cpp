// The Bullet engine's joints (bullet_joints.cpp): constraints solved with their bodies' island (a
// joined pair with no contact is one island), joined bodies that overlap make no contacts, the
// motor's limit taken per substep, and a restored engine continues with the same bits.
#include "engine_util.hpp"

#include <catch2/catch.hpp>

#include <cstring>

using namespace ssx;
using namespace ssx::test;

namespace {

std::unique_ptr<PhysicEngine> wheelOnArm(int substeps) {
  PhysicsSettings settings;
  settings.gravity = Vec3::Zero();
  settings.substeps = substeps;
  auto engine = makeEngine("bullet", settings);
  // an arm free in space, a wheel on a motor at its end (overlapping it)
  const int arm = addBox(*engine, Vec3(1.0, 0.1, 0.1), 1.0, Vec3(0, 0, 0));
  const int wheel = addBox(*engine, Vec3(0.2, 0.2, 0.05), 0.5, Vec3(0.5, 0, 0));
  EngineJoint hinge;
  hinge.kind = JointSpec::Kind::Hinge;
  hinge.parent = arm;
  hinge.child = wheel;
  hinge.frame.position = Vec3(0.5, 0, 0);
  engine->addJoint(hinge);
  engine->setJointMotor(0, 2.0, 0.05);
  return engine;
}

void run(PhysicEngine& engine, int n) {
  std::vector<Wrench> none(engine.bodyCount());
  for (int i = 0; i < n; ++i) engine.step(toNanoseconds(0.002), none);
}

}  // namespace

TEST_CASE("bullet joints: a motor turns a wheel against its arm, the pair free in space, momentum kept",
          "[bullet][joints]") {
  const int substeps = GENERATE(1, 4);
  INFO(substeps << " substeps");
  auto engine = wheelOnArm(substeps);
  run(*engine, 1000);
  const auto s = states(*engine);
  // the wheel turns at 2 rad/s relative to the arm about z; the arm turns back (no outside torque)
  CHECK(s[1].angular_velocity.z() - s[0].angular_velocity.z() == Approx(2.0).epsilon(0.01));
  CHECK(s[0].angular_velocity.z() < 0);
  CHECK(engine->contactCount() == 0);  // they overlap: joined, they do not collide
  // they stay joined at the hinge
  CHECK((s[0].pose.transformPoint(Vec3(0.5, 0, 0)) - s[1].pose.position).norm() < 1e-3);
}

TEST_CASE("bullet joints: a restored engine continues with the same bits", "[bullet][joints]") {
  auto one = wheelOnArm(2);
  run(*one, 200);
  const auto state = saved(*one);
  run(*one, 200);
  auto two = wheelOnArm(2);
  run(*two, 37);
  StateReader in(state);
  two->restoreState(in);
  run(*two, 200);
  const auto a = saved(*one), b = saved(*two);
  REQUIRE(a.size() == b.size());
  CHECK(std::memcmp(a.data(), b.data(), a.size()) == 0);
}
