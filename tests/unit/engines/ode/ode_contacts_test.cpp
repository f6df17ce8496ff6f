// The ODE engine's contacts (ode_contacts.cpp): how many a resting box makes and the per-pair
// limit on them, friction as set, and boxes that touch and push each other apart.
#include "engine_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace ssx;
using namespace ssx::test;

namespace {

// a 0.2 m box dropped onto the ground and left to settle for 1 s
std::unique_ptr<PhysicEngine> settledBox(PhysicsSettings settings) {
  auto engine = makeEngine("ode", settings);
  engine->addStatic({Shape::plane()}, Pose{});
  addBox(*engine, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(0, 0, 0.11));
  const std::vector<Wrench> none(1);
  for (int k = 0; k < 500; ++k) engine->step(toNanoseconds(0.002), none);
  return engine;
}

}  // namespace

TEST_CASE("ode contacts: a box resting on a face touches at its four corners, at most max_contacts",
          "[physics][ode]") {
  PhysicsSettings settings;
  const auto four = settledBox(settings);
  CHECK(four->contactCount() == 4);
  CHECK(states(*four).at(0).pose.position.z() == Approx(0.1).margin(0.002));
  settings.ode.max_contacts = 2;
  const auto two = settledBox(settings);
  CHECK(two->contactCount() == 2);
}

TEST_CASE("ode contacts: without friction a sliding box keeps its speed, with friction mu it stops", "[physics][ode]") {
  auto slide = [](double friction) {
    PhysicsSettings settings;
    settings.friction = friction;
    auto engine = settledBox(settings);
    BodyState s = states(*engine).at(0);
    s.linear_velocity = Vec3(1, 0, 0);
    engine->setState(0, s);
    const std::vector<Wrench> none(1);
    for (int k = 0; k < 250; ++k) engine->step(toNanoseconds(0.002), none);  // 0.5 s
    return states(*engine).at(0).linear_velocity.x();
  };
  CHECK(slide(0.0) == Approx(1.0).margin(1e-3));
  // mu g = 9.81 m/s^2 stops 1 m/s within 0.11 s
  CHECK(std::abs(slide(1.0)) < 1e-3);
}

TEST_CASE("ode contacts: two boxes placed overlapping are pushed apart and do not pass through", "[physics][ode]") {
  PhysicsSettings settings;
  settings.gravity = Vec3::Zero();
  auto engine = makeEngine("ode", settings);
  addBox(*engine, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(0, 0, 1));
  addBox(*engine, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(0.19, 0, 1));
  const std::vector<Wrench> none(2);
  engine->step(toNanoseconds(0.002), none);
  CHECK(engine->contactCount() > 0);
  for (int k = 0; k < 500; ++k) engine->step(toNanoseconds(0.002), none);
  const auto s = states(*engine);
  CHECK(s[1].pose.position.x() - s[0].pose.position.x() >= 0.2 - 0.002);
  // momentum is kept: they move apart symmetrically
  CHECK((s[0].linear_velocity + s[1].linear_velocity).norm() < 1e-9);
  CHECK(s[1].linear_velocity.x() > 0);
}
