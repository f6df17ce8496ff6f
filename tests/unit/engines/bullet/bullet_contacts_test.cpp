// The Bullet engine's contacts (bullet_contacts.cpp): a box dropped on the ground comes to rest on
// it; a kinematic body carries what rests on it and is solved in one island with it.
#include "engine_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace ssx;
using namespace ssx::test;

TEST_CASE("bullet: a dropped box comes to rest on the ground, touching it", "[physics][bullet]") {
  auto engine = makeEngine("bullet");
  engine->addStatic({Shape::plane()}, Pose{});
  addBox(*engine, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(0, 0, 0.5));
  const std::vector<Wrench> none(1);
  for (int k = 0; k < 1000; ++k) engine->step(toNanoseconds(0.002), none);
  const BodyState s = states(*engine).at(0);
  CHECK(s.pose.position.z() == Approx(0.1).margin(0.002));
  CHECK(s.linear_velocity.norm() < 1e-3);
  CHECK(engine->contactCount() >= 1);
}

TEST_CASE("bullet: boxes resting on one kinematic platform are solved together, the platform unmoved by them",
          "[physics][bullet][kinematic]") {
  // two boxes on one platform: one island (the platform joins it); each box is carried up with it
  auto engine = makeEngine("bullet");
  const int platform = addBox(*engine, Vec3(2, 1, 0.1), 5.0, Vec3::Zero());
  engine->setKinematic(platform);
  addBox(*engine, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(-0.5, 0, 0.15));
  addBox(*engine, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(0.5, 0, 0.15));
  BodyState up;
  up.linear_velocity = Vec3(0, 0, 0.2);
  engine->setState(platform, up);
  const std::vector<Wrench> none(3);
  for (int k = 0; k < 500; ++k) engine->step(toNanoseconds(0.002), none);
  const auto s = states(*engine);
  CHECK(s[0].pose.position.z() == Approx(0.2).margin(1e-9));  // 1 s at 0.2 m/s
  CHECK(s[0].linear_velocity.z() == 0.2);
  for (int i = 1; i <= 2; ++i) {
    CHECK(s[static_cast<std::size_t>(i)].pose.position.z() == Approx(0.35).margin(0.005));
    CHECK(s[static_cast<std::size_t>(i)].linear_velocity.z() == Approx(0.2).margin(0.02));
  }
}
