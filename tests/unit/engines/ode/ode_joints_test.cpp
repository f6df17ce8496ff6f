// The ODE engine's joints (ode_joints.cpp): joined bodies are pinned to world 0, whatever their home
// world, and stay joined; joined bodies that overlap make no contacts; a restored engine makes its
// joints again with the frames they had, so that it continues with the same bits.
#include "engine_util.hpp"

#include <catch2/catch.hpp>

#include <cstring>
#include <numbers>

using namespace ssx;
using namespace ssx::test;

namespace {

// a box hung from the world by a hinge about y at `pivot`, and a second box joined to it by a ball
// joint; `spacer` free bodies between them so that their home worlds differ
struct Rig {
  std::unique_ptr<PhysicEngine> engine = makeEngine("ode");
  int first = 0, second = 0;
  explicit Rig(int spacer) {
    const Vec3 pivot(0, 0, 2);
    first = addBox(*engine, Vec3(0.1, 0.1, 0.5), 1.0, pivot + Vec3(0.25, 0, 0));
    for (int i = 0; i < spacer; ++i) addBox(*engine, Vec3(0.1, 0.1, 0.1), 1.0, Vec3(10 + i, 0, 0));
    second = addBox(*engine, Vec3(0.1, 0.1, 0.5), 1.0, pivot + Vec3(0.5, 0, -0.2));  // overlaps the first
    EngineJoint hinge;
    hinge.kind = JointSpec::Kind::Hinge;
    hinge.child = first;
    hinge.frame = Pose{pivot, Quat(Eigen::AngleAxisd(-std::numbers::pi / 2, Vec3::UnitX()))};  // z along y
    CHECK(engine->addJoint(hinge) == 0);
    EngineJoint ball;
    ball.kind = JointSpec::Kind::Ball;
    ball.parent = first;
    ball.child = second;
    ball.frame.position = pivot + Vec3(0.5, 0, 0);
    CHECK(engine->addJoint(ball) == 1);
    CHECK(engine->jointCount() == 2);
  }
  void step(int n) {
    std::vector<Wrench> none(engine->bodyCount());
    for (int i = 0; i < n; ++i) engine->step(toNanoseconds(0.001), none);
  }
};

}  // namespace

TEST_CASE("ode joints: bodies of different home worlds stay joined, and joined bodies make no contacts",
          "[ode][joints]") {
  Rig rig(200);  // bodies 0 and 201: home worlds 0 and 3
  rig.step(500);
  const auto s = states(*rig.engine);
  const BodyState& a = s[static_cast<std::size_t>(rig.first)];
  const BodyState& b = s[static_cast<std::size_t>(rig.second)];
  // the hinge holds the first box's end at the pivot; the ball holds the second's at the first's
  CHECK((a.pose.transformPoint(Vec3(-0.25, 0, 0)) - Vec3(0, 0, 2)).norm() < 1e-3);
  CHECK((a.pose.transformPoint(Vec3(0.25, 0, 0)) - b.pose.transformPoint(Vec3(0, 0, 0.2))).norm() < 1e-3);
  CHECK(a.pose.position.z() < 2.0 - 0.1);  // it swung down
  CHECK(rig.engine->contactCount() == 0);   // the two boxes overlap: joined, they do not collide
}

TEST_CASE("ode joints: a restored engine makes its joints again and continues with the same bits", "[ode][joints]") {
  Rig one(200);
  one.step(300);
  const auto state = saved(*one.engine);
  one.step(300);
  Rig two(200);
  two.step(50);  // elsewhere when restored
  StateReader in(state);
  two.engine->restoreState(in);
  two.step(300);
  const auto a = saved(*one.engine), b = saved(*two.engine);
  REQUIRE(a.size() == b.size());
  CHECK(std::memcmp(a.data(), b.data(), a.size()) == 0);
}
