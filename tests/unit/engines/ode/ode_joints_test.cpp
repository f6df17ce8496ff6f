// The ODE engine's joints (ode_joints.cpp): joined bodies step in their articulation's world and
// stay joined; joined bodies that overlap make no contacts; articulations of different worlds that
// touch are solved together, on any number of threads; a restored engine makes its joints again
// with the frames they had, so that it continues with the same bits.
#include "engine_util.hpp"

#include "base/worker_pool.hpp"

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

namespace {

// four pairs of boxes on the ground, each pair joined by a ball joint, 70 free boxes far away
// before each pair so that every pair has a home world of its own; the pairs pushed at each
// other, 0 against 1 and 2 against 3
struct Pairs {
  static constexpr int kPairs = 4, kSpacers = 70;
  std::unique_ptr<PhysicEngine> engine = makeEngine("ode");
  std::vector<int> first;
  std::vector<Wrench> push;
  Pairs() {
    engine->addStatic({Shape::plane()}, Pose{});
    for (int p = 0; p < kPairs; ++p) {
      for (int k = 0; k < kSpacers; ++k)
        addBox(*engine, Vec3(0.1, 0.1, 0.1), 0.2, Vec3(20 + 0.3 * (k % 10), 0.3 * (k / 10) + 3 * p, 0.05));
      const double x = 0.6 * p;
      const int a = addBox(*engine, Vec3(0.2, 0.2, 0.2), 0.5, Vec3(x, 0, 0.1));
      const int b = addBox(*engine, Vec3(0.2, 0.2, 0.2), 0.5, Vec3(x, 0.25, 0.1));
      EngineJoint ball;
      ball.kind = JointSpec::Kind::Ball;
      ball.parent = a;
      ball.child = b;
      ball.frame.position = Vec3(x, 0.125, 0.1);
      engine->addJoint(ball);
      first.push_back(a);
    }
    push.resize(engine->bodyCount());
    for (int p = 0; p < kPairs; ++p)
      for (int k = 0; k < 2; ++k)
        push[static_cast<std::size_t>(first[static_cast<std::size_t>(p)] + k)].force =
            Vec3(p % 2 == 0 ? 8.0 : -8.0, 0, 0);
  }
  void step(int n) {
    for (int i = 0; i < n; ++i) engine->step(toNanoseconds(0.005), push);
  }
};

}  // namespace

TEST_CASE(
    "ode joints: articulations of different home worlds pushed into each other: held, and the same bits on 1, 2 and 4 "
    "threads and after a restore in contact",
    "[ode][joints][parallel]") {
  std::vector<BodyState> reference;
  std::vector<std::byte> state, reference_bits;
  bool touched = false;
  for (unsigned threads : {1u, 2u, 4u}) {
    INFO(threads << " threads");
    ssx::detail::WorkerPool pool(threads);
    Pairs pairs;
    pairs.engine->setTaskRunner(&pool);
    pairs.engine->recordContacts(true);
    for (int k = 0; k < 300; ++k) {
      pairs.step(1);
      // a box of pair 0 against one of pair 1 (their bodies: 70 apart and more)
      for (const EngineContact& c : pairs.engine->contacts())
        touched = touched || (c.body_b >= 0 && c.body_b - c.body_a > 2);
      if (k == 149 && threads == 1) {
        StateWriter w(state);
        pairs.engine->saveState(w);
      }
    }
    const auto s = states(*pairs.engine);
    for (const int a : pairs.first) {  // each pair still joined at its ball
      const BodyState& p = s[static_cast<std::size_t>(a)];
      const BodyState& q = s[static_cast<std::size_t>(a + 1)];
      CHECK((p.pose.transformPoint(Vec3(0, 0.125, 0)) - q.pose.transformPoint(Vec3(0, -0.125, 0))).norm() < 1e-3);
    }
    // every body's state, each world's order and random seed: the engine's whole saved state
    if (threads == 1) {
      reference = s;
      reference_bits = saved(*pairs.engine);
    } else {
      CHECK(saved(*pairs.engine) == reference_bits);
    }
  }
  REQUIRE(touched);
  // pair 0 pushed pair 1 back or was stopped by it: it is not where pushing alone takes it (2.7 m)
  CHECK(reference[0 + Pairs::kSpacers].pose.position.x() < 1.0);
  ssx::detail::WorkerPool pool(2);
  Pairs restored;
  restored.engine->setTaskRunner(&pool);
  restored.step(20);  // elsewhere when restored
  StateReader in(state);
  restored.engine->restoreState(in);
  restored.step(150);
  CHECK(saved(*restored.engine) == reference_bits);
}
