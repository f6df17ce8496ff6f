// The Bullet engine's ray queries (bullet_rays.cpp): Bullet's single-object ray test against the
// shapes the grid finds and the planes; a body Bullet holds on its principal axes (its inertia not
// diagonal in ssx's frame) is met where it is; an ignored range of bodies is not met.
#include "engine_util.hpp"

#include <catch2/catch.hpp>

using namespace ssx;
using namespace ssx::test;

TEST_CASE("bullet rays: a ray meets the nearest shape not ignored, bodies on principal axes too, and the ground",
          "[bullet][rays]") {
  auto engine = makeEngine("bullet");
  engine->addStatic({Shape::plane()}, Pose{});
  // a long box turned 45 degrees about z, with an inertia given in its own axes turned too: Bullet
  // keeps it on other axes than ssx's
  MassProperties m;
  m.mass = 1;
  const Mat3 r = Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()).toRotationMatrix();
  m.inertia = r * Vec3(0.01, 0.1, 0.1).asDiagonal() * r.transpose();
  BodyState s;
  s.pose.position = Vec3(1, 0, 0.5);
  const int turned = engine->addBody(m, {Shape::box(Vec3(1, 0.1, 0.1))}, s);  // along x in ssx's frame
  const int far = addBox(*engine, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(3, 0, 0.5));
  engine->prepareRayQueries();
  const Ray rays[] = {{Vec3(0, 0, 0.5), Vec3(5, 0, 0.5)}, {Vec3(0, 0, 0.5), Vec3(0, 0, -1)}};
  RayHit hits[2];
  engine->castRays(rays, hits, 0, 0);
  CHECK(hits[0].body == turned);
  CHECK(hits[0].distance == Approx(0.5).margin(1e-6));  // its end, 0.5 m before its centre
  CHECK(hits[1].body == -1);
  CHECK(hits[1].distance == Approx(0.5).margin(1e-6));
  engine->castRays(rays, hits, turned, turned + 1);
  CHECK(hits[0].body == far);
  CHECK(hits[0].distance == Approx(2.9).margin(1e-6));
}
