// The Bullet engine through ssx::PhysicEngine alone: semi-implicit Euler under a force, states set
// and read back exactly, and a restored engine continuing bitwise; a state of the other engine is refused.
#include "engine_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace ssx;
using namespace ssx::test;

TEST_CASE("bullet: a pushed body follows semi-implicit Euler, gravity included", "[physics][bullet]") {
  auto engine = makeEngine("bullet");
  CHECK(engine->name() == "bullet");
  const int body = addBox(*engine, Vec3(0.1, 0.1, 0.1), 2.0, Vec3(0, 0, 100));
  const std::vector<Wrench> push{{Vec3(4, 0, 0), Vec3::Zero()}};
  const double dt = 0.01;
  for (int k = 0; k < 50; ++k) engine->step(toNanoseconds(dt), push);
  const BodyState s = states(*engine).at(static_cast<std::size_t>(body));
  // v_n = n a dt, x_n = x_0 + a dt^2 n (n + 1) / 2
  CHECK(s.linear_velocity.x() == Approx(50 * 2.0 * dt).epsilon(1e-9));
  CHECK(s.linear_velocity.z() == Approx(-50 * 9.81 * dt).epsilon(1e-9));
  CHECK(s.pose.position.x() == Approx(2.0 * dt * dt * 50 * 51 / 2).epsilon(1e-9));
  CHECK(s.pose.position.z() == Approx(100 - 9.81 * dt * dt * 50 * 51 / 2).epsilon(1e-9));
}

TEST_CASE("bullet: a state set is read back to the bit", "[physics][bullet]") {
  auto engine = makeEngine("bullet");
  addBox(*engine, Vec3(0.1, 0.2, 0.3), 1.0, Vec3::Zero());
  BodyState s;
  s.pose.position = Vec3(1.25, -3.5, 0.75);
  s.pose.orientation = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  s.linear_velocity = Vec3(0.1, 0.2, 0.3);
  s.angular_velocity = Vec3(-1, 0.5, 2);
  engine->setState(0, s);
  const BodyState r = states(*engine).at(0);
  CHECK(r.pose.position == s.pose.position);
  CHECK(r.linear_velocity == s.linear_velocity);
  CHECK(r.angular_velocity == s.angular_velocity);
  CHECK(r.pose.orientation.angularDistance(s.pose.orientation) < 1e-15);
}

TEST_CASE("bullet: a restored engine continues bitwise, the other engine's state is refused", "[physics][bullet][state]") {
  auto build = [] {
    auto e = makeEngine("bullet");
    e->addStatic({Shape::plane()}, Pose{});
    for (int i = 0; i < 6; ++i) addBox(*e, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(0.05 * i, 0, 0.3 + 0.25 * i));
    return e;
  };
  const std::vector<Wrench> none(6);
  auto first = build();
  for (int k = 0; k < 200; ++k) first->step(toNanoseconds(0.002), none);
  const std::vector<std::byte> at200 = saved(*first);
  for (int k = 0; k < 200; ++k) first->step(toNanoseconds(0.002), none);

  auto second = build();
  StateReader in(at200);
  second->restoreState(in);
  for (int k = 0; k < 200; ++k) second->step(toNanoseconds(0.002), none);
  CHECK(saved(*second) == saved(*first));

  auto ode = makeEngine("ode");
  ode->addStatic({Shape::plane()}, Pose{});
  for (int i = 0; i < 6; ++i) addBox(*ode, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(0.05 * i, 0, 0.3 + 0.25 * i));
  StateReader foreign(at200);
  CHECK_THROWS_AS(ode->restoreState(foreign), StateError);
}
