// Ray queries (rays.cpp and each engine's): rays meet boxes, spheres, cylinders, capsules and
// planes, static or moving, at the distance geometry gives, on ODE and Bullet alike; the caster's
// own bodies are ignored; the shapes are where the snapshot has them, also after a body was moved
// between steps; rays cast from many threads at once give what one thread gives.
#include "test_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <thread>
#include <vector>

using namespace ssx;
using Catch::Contains;

namespace {

struct World {
  std::unique_ptr<Environment> env;
  Artifact* ball = nullptr;
  Artifact* caster = nullptr;
  explicit World(const std::string& engine) {
    EnvironmentSettings s;
    s.physics.engine = engine;
    s.physics.gravity = Vec3::Zero();
    env = std::make_unique<Environment>(s);
    PhysicNodeSpec statics;
    statics.name = "statics";
    statics.is_static = true;
    statics.shapes.push_back(Shape::plane());
    statics.shapes.push_back(Shape::box(Vec3(1, 1, 1), Pose{Vec3(5, 0, 0.5), Quat::Identity()}));
    statics.shapes.push_back(Shape::cylinder(0.5, 2, Pose{Vec3(0, 5, 1), Quat::Identity()}));
    statics.shapes.push_back(Shape::capsule(0.25, 1, Pose{Vec3(-5, 0, 1), Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()))}));
    env->addArtifact("statics").addPhysicRoot(statics);
    PhysicNodeSpec ball_spec;
    ball_spec.name = "ball";
    ball_spec.shapes.push_back(Shape::sphere(0.3));
    ball_spec.mass = 1;
    ball = &env->addArtifact("ball", Pose{Vec3(0, -5, 1), Quat::Identity()});
    ball->addPhysicRoot(ball_spec);
    PhysicNodeSpec own = ball_spec;
    own.name = "own";
    caster = &env->addArtifact("caster", Pose{Vec3(0, 0, 1), Quat::Identity()});
    caster->addPhysicRoot(own);
    env->enableRayQueries();
    env->step();
  }
  RayHit cast(const Vec3& from, const Vec3& to, const Artifact* ignore = nullptr) const {
    const Ray ray{from, to};
    RayHit hit;
    env->castRays({&ray, 1}, {&hit, 1}, ignore);
    return hit;
  }
};

}  // namespace

TEST_CASE("rays: each kind of shape is met where geometry puts it, on both engines", "[rays]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  World w(engine);
  const Vec3 o(0, 0, 1);
  // from the caster's centre, its own ball ignored
  const RayHit box = w.cast(o, o + Vec3(10, 0, 0), w.caster);
  CHECK(box.hit);
  CHECK(box.distance == Approx(4.5).margin(1e-6));
  CHECK(box.body == -1);
  CHECK(box.normal.isApprox(Vec3(-1, 0, 0), 1e-6));
  CHECK(w.cast(o, o + Vec3(0, 10, 0), w.caster).distance == Approx(4.5).margin(1e-6));   // cylinder side
  // a capsule lying along y (Bullet casts at convex shapes with its subsimplex convex cast: within 1 mm)
  CHECK(w.cast(o, o + Vec3(-10, 0, 0), w.caster).distance == Approx(4.75).margin(engine == "ode" ? 1e-6 : 1e-3));
  const RayHit ball = w.cast(o, o + Vec3(0, -10, 0), w.caster);
  CHECK(ball.distance == Approx(4.7).margin(1e-6));
  CHECK(ball.body == w.ball->root().bodyIndex());
  CHECK(ball.point.isApprox(Vec3(0, -4.7, 1), 1e-6));
  CHECK(w.cast(o, o + Vec3(0, 0, -10), w.caster).distance == Approx(1.0).margin(1e-6));  // the plane
  // too short to reach, or pointing at nothing
  CHECK_FALSE(w.cast(o, o + Vec3(4, 0, 0), w.caster).hit);
  CHECK_FALSE(w.cast(o, o + Vec3(0, 0, 10), w.caster).hit);
  // not ignored, the caster's own ball is met first (from inside: where the engines report it)
  CHECK(w.cast(o + Vec3(-1, 0, 0), o + Vec3(10, 0, 0)).distance == Approx(0.7).margin(1e-6));
}

TEST_CASE("rays: shapes are where the snapshot has them: after a step, and after a body is moved between steps",
          "[rays]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  World w(engine);
  w.ball->root().setVelocity(Vec3(0, 1, 0), Vec3::Zero());  // toward the caster
  w.env->step(1000);  // 1 s: 1 m nearer
  const Vec3 o(0, 0, 1);
  CHECK(w.cast(o, o + Vec3(0, -10, 0), w.caster).distance == Approx(3.7).margin(1e-3));
  BodyState moved = w.env->bodyState(w.ball->root().bodyIndex());
  moved.pose.position = Vec3(0, -2, 1);
  w.env->setBodyState(w.ball->root().bodyIndex(), moved);
  CHECK(w.cast(o, o + Vec3(0, -10, 0), w.caster).distance == Approx(1.7).margin(1e-9));
}

TEST_CASE("rays: cast from several threads at once, rays give what one thread gives", "[rays]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  World w(engine);
  std::vector<Ray> rays;
  for (int k = 0; k < 720; ++k) {
    const double a = k * M_PI / 360;
    rays.push_back({Vec3(0, 0, 1), Vec3(0, 0, 1) + 8.0 * Vec3(std::cos(a), std::sin(a), -0.2)});
  }
  std::vector<RayHit> alone(rays.size());
  w.env->castRays(rays, alone, w.caster);
  std::vector<std::vector<RayHit>> parallel(4, std::vector<RayHit>(rays.size()));
  {
    std::vector<std::jthread> threads;
    for (auto& out : parallel) threads.emplace_back([&w, &rays, &out] { w.env->castRays(rays, out, w.caster); });
  }
  for (const auto& out : parallel)
    for (std::size_t k = 0; k < rays.size(); ++k) {
      CHECK(out[k].hit == alone[k].hit);
      CHECK(out[k].distance == alone[k].distance);
    }
  std::size_t hits = 0;
  for (const auto& h : alone) hits += h.hit ? 1 : 0;
  CHECK(hits == rays.size());  // every one meets a shape or, tilted down, the plane
}

TEST_CASE("rays: casting needs ray queries on, and one hit per ray", "[rays]") {
  Environment env;
  env.addArtifact("a").addPhysicRoot(ssx::test::boxBody(Vec3(1, 1, 1), 1));
  env.step();
  Ray ray;
  RayHit hit;
  CHECK_THROWS_WITH(env.castRays({&ray, 1}, {&hit, 1}), Contains("not enabled"));
  env.enableRayQueries();
  CHECK_THROWS_WITH(env.castRays({&ray, 1}, {}), Contains("one hit per ray"));
}
