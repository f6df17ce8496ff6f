// Engine factories: the engines a build offers, by name; an unknown name lists the ones there are;
// the null renderer draws nothing and says how to get images. What every engine must do alike:
// kinematic bodies (moved only by setState, infinitely heavy to what touches them).
#include "engine_util.hpp"

#include <ssx/physic_engine.hpp>
#include <ssx/render.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>

using namespace ssx;
using Catch::Contains;
using namespace ssx::test;

TEST_CASE("engines: every physics engine offered by name is made under that name", "[engines]") {
  const auto names = physicEngineNames();
  CHECK(names == std::vector<std::string>{"ode", "bullet"});
  for (const auto& name : names) {
    PhysicsSettings settings;
    settings.engine = name;
    const auto engine = createPhysicEngine(settings);
    REQUIRE(engine != nullptr);
    CHECK(engine->name() == name);
  }
  PhysicsSettings wrong;
  wrong.engine = "physx";
  CHECK_THROWS_WITH(createPhysicEngine(wrong), Contains("unknown physics engine 'physx' (available: ode, bullet)"));
}

TEST_CASE("engines: the null renderer draws no pixels, unknown renderers list those there are", "[engines][render]") {
  const auto names = renderEngineNames();
  REQUIRE(std::find(names.begin(), names.end(), "null") != names.end());
  RenderSettings settings;
  const auto null = createRenderEngine(settings);
  CHECK(null->name() == "null");
  CHECK_FALSE(null->drawsPixels());
  Image image;
  CHECK_THROWS_WITH(null->renderView(CameraView{}, {}, Color{}, image), Contains("engine=\"osmesa\""));
  settings.engine = "vulkan";
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  CHECK_THROWS_WITH(createRenderEngine(settings), Contains("unknown render engine 'vulkan' (available: " + list + ")"));
}

TEST_CASE("engines: a kinematic body moves at its set velocity, whatever pushes it", "[engines][kinematic]") {
  const std::string name = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(name);
  auto engine = makeEngine(name);
  engine->addStatic({Shape::plane()}, Pose{});
  const int k = addBox(*engine, Vec3(0.5, 0.5, 0.5), 2.0, Vec3(0, 0, 0.2));  // in the ground: no contact
  const int other = addBox(*engine, Vec3(0.5, 0.5, 0.5), 2.0, Vec3(0.3, 0, 0.2));  // overlaps it
  engine->setKinematic(k);
  engine->setKinematic(other);
  CHECK(engine->isKinematic(k));
  CHECK_FALSE(engine->isKinematic(addBox(*engine, Vec3(0.1, 0.1, 0.1), 1.0, Vec3(5, 5, 5))));
  BodyState s;
  s.pose.position = Vec3(0, 0, 0.2);
  s.linear_velocity = Vec3(1, 0, 0);
  s.angular_velocity = Vec3(0, 0, 0.5);
  engine->setState(k, s);
  const std::vector<Wrench> push{{Vec3(100, 0, 0), Vec3(0, 0, 10)}, {Vec3(0, 100, 0), Vec3::Zero()}, {}};
  for (int i = 0; i < 100; ++i) engine->step(toNanoseconds(0.01), push);
  const auto now = states(*engine);
  CHECK(now[0].pose.position.x() == Approx(1.0).margin(1e-9));
  CHECK(now[0].pose.position.z() == Approx(0.2).margin(1e-12));  // no gravity, no ground
  CHECK(now[0].linear_velocity == Vec3(1, 0, 0));
  CHECK(now[0].angular_velocity == Vec3(0, 0, 0.5));
  const double yaw = 2 * std::atan2(now[0].pose.orientation.z(), now[0].pose.orientation.w());
  CHECK(yaw == Approx(0.5).margin(1e-6));
  CHECK(now[1].pose.position == Vec3(0.3, 0, 0.2));  // never set moving: still where it was
  CHECK(engine->contactCount() == 0);  // kinematic against static, kinematic against kinematic: nothing
}

TEST_CASE("engines: what rests on a kinematic platform is carried, what hits a kinematic wall stops, the wall does not",
          "[engines][kinematic]") {
  const std::string name = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(name);
  auto engine = makeEngine(name);
  const int platform = addBox(*engine, Vec3(1, 1, 0.1), 1.0, Vec3::Zero());
  const int load = addBox(*engine, Vec3(0.2, 0.2, 0.2), 10.0, Vec3(0, 0, 0.15));  // ten times the platform
  const int wall = addBox(*engine, Vec3(0.1, 2, 2), 0.1, Vec3(3, 0, 5));
  const int ball = addBox(*engine, Vec3(0.2, 0.2, 0.2), 50.0, Vec3(2.5, 0, 5));
  engine->setKinematic(platform);
  engine->setKinematic(wall);
  BodyState rising;
  rising.linear_velocity = Vec3(0, 0, 0.3);
  engine->setState(platform, rising);
  BodyState thrown;
  thrown.pose.position = Vec3(2.5, 0, 5);
  thrown.linear_velocity = Vec3(4, 0, 0);
  engine->setState(ball, thrown);
  std::vector<Wrench> hold(4);
  hold[static_cast<std::size_t>(ball)].force = Vec3(0, 0, 50 * 9.81);  // the ball flies level
  for (int i = 0; i < 500; ++i) engine->step(toNanoseconds(0.002), hold);
  const auto s = states(*engine);
  CHECK(s[static_cast<std::size_t>(platform)].pose.position.z() == Approx(0.3).margin(1e-9));
  CHECK(s[static_cast<std::size_t>(load)].pose.position.z() == Approx(0.45).margin(0.01));
  CHECK(s[static_cast<std::size_t>(load)].linear_velocity.z() == Approx(0.3).margin(0.03));
  CHECK(s[static_cast<std::size_t>(wall)].pose.position == Vec3(3, 0, 5));
  CHECK(s[static_cast<std::size_t>(ball)].pose.position.x() < 2.85 + 0.01);  // stopped at the wall's face
  CHECK(s[static_cast<std::size_t>(ball)].linear_velocity.x() < 0.1);
}

TEST_CASE("engines: an engine with kinematic bodies in contact restores and continues bitwise", "[engines][kinematic][state]") {
  const std::string name = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(name);
  auto build = [&] {
    auto e = makeEngine(name);
    e->addStatic({Shape::plane()}, Pose{});
    const int platform = addBox(*e, Vec3(1, 1, 0.1), 1.0, Vec3(0, 0, 0.3));
    e->setKinematic(platform);
    BodyState turning;
    turning.pose.position = Vec3(0, 0, 0.3);
    turning.angular_velocity = Vec3(0, 0, 1);
    e->setState(platform, turning);
    for (int i = 0; i < 4; ++i) addBox(*e, Vec3(0.15, 0.15, 0.15), 1.0, Vec3(0.3 * (i % 2) - 0.15, 0.3 * (i / 2) - 0.15, 0.5));
    return e;
  };
  const std::vector<Wrench> none(5);
  auto first = build();
  for (int k = 0; k < 200; ++k) first->step(toNanoseconds(0.002), none);
  const std::vector<std::byte> at200 = saved(*first);
  for (int k = 0; k < 200; ++k) first->step(toNanoseconds(0.002), none);
  auto second = build();
  StateReader in(at200);
  second->restoreState(in);
  for (int k = 0; k < 200; ++k) second->step(toNanoseconds(0.002), none);
  CHECK(saved(*second) == saved(*first));
  CHECK(first->contactCount() > 0);
  // the boxes turn with the platform (friction), the platform as set
  const auto s = states(*first);
  CHECK(s[0].angular_velocity == Vec3(0, 0, 1));
  CHECK(s[1].angular_velocity.z() == Approx(1).margin(0.1));
}
