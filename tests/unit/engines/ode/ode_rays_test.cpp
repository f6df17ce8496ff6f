// The ODE engine's ray queries (ode_rays.cpp): ODE's ray geom against the shapes the grid finds and
// the planes; an ignored range of bodies is not met; a ray of no length meets nothing.
#include "engine_util.hpp"

#include <catch2/catch.hpp>

using namespace ssx;
using namespace ssx::test;

TEST_CASE("ode rays: a ray meets the nearest shape not ignored, and the ground", "[ode][rays]") {
  auto engine = makeEngine("ode");
  engine->addStatic({Shape::plane()}, Pose{});
  const int near = addBox(*engine, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(1, 0, 0.5));
  const int far = addBox(*engine, Vec3(0.2, 0.2, 0.2), 1.0, Vec3(2, 0, 0.5));
  engine->prepareRayQueries();
  const Ray rays[] = {{Vec3(0, 0, 0.5), Vec3(5, 0, 0.5)}, {Vec3(0, 0, 0.5), Vec3(0, 0, -1)}, {Vec3(1, 1, 1), Vec3(1, 1, 1)}};
  RayHit hits[3];
  engine->castRays(rays, hits, 0, 0);
  CHECK(hits[0].body == near);
  CHECK(hits[0].distance == Approx(0.9));
  CHECK(hits[1].body == -1);
  CHECK(hits[1].distance == Approx(0.5));
  CHECK_FALSE(hits[2].hit);
  engine->castRays(rays, hits, near, near + 1);  // the near box ignored
  CHECK(hits[0].body == far);
  CHECK(hits[0].distance == Approx(1.9));
}
