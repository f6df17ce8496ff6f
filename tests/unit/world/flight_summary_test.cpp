// The flight summary: end states (airborne, landed, crashed), touches between robots counted once
// per touch with the first one's time and pair, the closest approach and the distance flown.
#include <ssx/ssx.hpp>

#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <numbers>

using namespace ssx;
using ssx::test::at;
using ssx::test::boxBody;

namespace {

Artifact& addBox(Environment& env, const std::string& name, const Pose& pose) {
  Artifact& a = env.addArtifact(name, pose);
  a.addPhysicRoot(boxBody(Vec3(0.2, 0.2, 0.2), 1.0));  // reach: half the diagonal, 0.173 m
  return a;
}

}  // namespace

TEST_CASE("flight summary: a box on its side crashed, one resting on the ground landed, one high up flies",
          "[flight_summary]") {
  Environment env;
  env.addGround();
  addBox(env, "resting", at(0, 0, 0.1));
  addBox(env, "tipped", {Vec3(3, 0, 0.1), Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()))});
  Artifact& high = addBox(env, "high", at(6, 0, 5));
  high.setDriver(std::make_unique<test::LambdaDriver>([](Driver& d, const StepInfo&) {
    d.artifact().root().addForce(Vec3(0, 0, 9.81));  // weightless: it stays up
  }));
  FlightRecorder recorder;
  for (int k = 0; k < 100; ++k) {
    env.step(10);
    recorder.observe(env);
  }
  const FlightSummary s = recorder.summary();
  CHECK(s.robots == 3);
  CHECK(s.landed == 1);
  CHECK(s.crashed == 1);
  CHECK(s.airborne == 1);
  CHECK(s.crashed_names == std::vector<std::string>{"tipped"});
  CHECK(s.collisions == 0);
  CHECK(s.closest_approach_m == Approx(3.0).margin(0.01));
  CHECK(s.samples == 100);
  CHECK_THAT(s.str(), Catch::StartsWith("robots 3: airborne 1, landed 1, crashed 1 (tipped); collisions 0; closest "
                                        "approach 3.00 m (resting and tipped)"));
}

TEST_CASE("flight summary: robots that come within reach of each other touch, once per touch", "[flight_summary]") {
  EnvironmentSettings settings;
  settings.physics.gravity = Vec3::Zero();
  Environment env(settings);
  // two boxes moving towards each other at 1 m/s each, from 2 m apart: they meet after about 0.83 s
  Artifact& a = addBox(env, "a", at(-1, 0, 1));
  Artifact& b = addBox(env, "b", at(1, 0, 1));
  addBox(env, "far", at(0, 50, 1));
  env.step();
  BodyState s = a.root().state();
  s.linear_velocity = Vec3(1, 0, 0);
  env.setBodyState(a.root().bodyIndex(), s);
  s = b.root().state();
  s.linear_velocity = Vec3(-1, 0, 0);
  env.setBodyState(b.root().bodyIndex(), s);
  FlightRecorder recorder;
  for (int k = 0; k < 200; ++k) {
    env.step(10);  // 0.01 s with the default 1 ms step
    recorder.observe(env);
  }
  const FlightSummary f = recorder.summary();
  CHECK(f.collisions == 1);
  CHECK(f.first_collision_pair == "a and b");
  // they touch when the centres are 0.346 m apart: after (2 - 0.346) / 2 s = 0.827 s
  CHECK(f.first_collision_s == Approx(0.83).margin(0.02));
  CHECK(f.closest_approach_m < 0.25);
  CHECK(f.closest_pair == "a and b");
  CHECK(f.mean_distance_flown_m > 0.5);
  CHECK_THAT(f.str(), Catch::Contains("collisions 1, first at 0.8") && Catch::Contains("(a and b)"));
}

TEST_CASE("flight summary: a robot dropped onto the ground crashed, one set down gently landed, an impact counts once",
          "[flight_summary]") {
  Environment env;
  env.addGround();
  // from 2 m: it meets the ground at about 6 m/s and stops within a few steps; from 2 cm above
  // touching it: 0.6 m/s, less than the 1 m/s an impact takes
  addBox(env, "dropped", at(0, 0, 2.1));
  addBox(env, "set_down", at(3, 0, 0.12));
  FlightRecorder recorder;
  for (int k = 0; k < 150; ++k) {  // 1.5 s, observed every 10 ms
    env.step(10);
    recorder.observe(env);
  }
  const FlightSummary s = recorder.summary();
  CHECK(s.crashed == 1);
  CHECK(s.crashed_names == std::vector<std::string>{"dropped"});
  CHECK(s.landed == 1);
  CHECK(s.impacts == 1);
  CHECK(s.hardest_impact_robot == "dropped");
  // at least the speed it fell at less what 4 g explain in 10 ms; more when the contact throws it
  // back up a little (ODE pushes the sinking box out)
  const double fall = std::sqrt(2 * 9.81 * 1.9);
  CHECK(s.hardest_impact_mps > fall - 4 * 9.81 * 0.01 - 0.1);
  CHECK(s.hardest_impact_mps < 1.5 * fall);
  CHECK_THAT(s.str(), Catch::Contains("crashed 1 (dropped)") && Catch::Contains("; impacts 1, hardest "));
}

TEST_CASE("flight summary: a robot that bumps an obstacle in flight and flies on is airborne, with its impact counted",
          "[flight_summary]") {
  EnvironmentSettings settings;
  settings.physics.gravity = Vec3::Zero();
  Environment env(settings);
  env.addGround();
  // a wall; a box flies into it at 3 m/s, 1 m above the ground, and bounces back
  Artifact& wall = env.addArtifact("wall", at(2, 0, 1));
  PhysicNodeSpec slab;
  slab.name = "slab";
  slab.is_static = true;
  slab.shapes.push_back(Shape::box(Vec3(0.2, 4, 2)));
  wall.addPhysicRoot(std::move(slab));
  Artifact& flyer = addBox(env, "flyer", at(0, 0, 1));
  env.start();
  BodyState moving = flyer.root().state();
  moving.linear_velocity = Vec3(3, 0, 0);
  env.setBodyState(flyer.root().bodyIndex(), moving);
  FlightRecorder recorder;
  recorder.observe(env);
  for (int k = 0; k < 100; ++k) {
    env.step(10);
    recorder.observe(env);
  }
  const FlightSummary s = recorder.summary();
  CHECK(s.robots == 1);
  CHECK(s.impacts == 1);
  CHECK(s.hardest_impact_robot == "flyer");
  CHECK(s.hardest_impact_mps > 1.0);
  CHECK(s.airborne == 1);  // not on the ground: an impact alone is not a crash
  CHECK(s.crashed == 0);
}

namespace {

// a wheeled robot's driver, as diff_drive (the summary recognises one by OdometryInterface)
class Wheels final : public Driver, public OdometryInterface {
 public:
  void step(const StepInfo&) override {}
  Odometry odometry() const override { return {}; }
};

}  // namespace

TEST_CASE("flight summary: wheeled robots are on wheels, not landed or airborne, whatever their height, tipped over "
          "they crashed, a robot resting on another landed",
          "[flight_summary]") {
  Environment env;
  env.addGround();
  addBox(env, "on_floor", at(0, 0, 0.1)).setDriver(std::make_unique<Wheels>());
  // on a table (a static box 0.5 m high): a quadrotor's rule would call it airborne
  Artifact& table = env.addArtifact("table", at(3, 0, 0.25));
  PhysicNodeSpec top;
  top.name = "top";
  top.is_static = true;
  top.shapes.push_back(Shape::box(Vec3(1, 1, 0.5)));
  table.addPhysicRoot(std::move(top));
  addBox(env, "on_table", at(3, 0, 0.6)).setDriver(std::make_unique<Wheels>());
  addBox(env, "tipped", {Vec3(6, 0, 0.1), Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()))})
      .setDriver(std::make_unique<Wheels>());
  addBox(env, "box", at(9, 0, 0.1));  // no driver: landed, as before
  addBox(env, "stacked", at(9, 0, 0.3));  // resting on "box": landed too, 0.2 m above the ground
  FlightRecorder recorder;
  for (int k = 0; k < 50; ++k) {
    env.step(10);
    recorder.observe(env);
  }
  const FlightSummary s = recorder.summary();
  CHECK(s.robots == 5);
  CHECK(s.on_wheels == 2);
  CHECK(s.landed == 2);
  CHECK(s.airborne == 0);
  CHECK(s.crashed == 1);
  CHECK(s.crashed_names == std::vector<std::string>{"tipped"});
  CHECK_THAT(s.str(), Catch::StartsWith("robots 5: airborne 0, landed 2, on wheels 2, crashed 1 (tipped); "));
}

TEST_CASE("flight summary: ground robots touch by their footprints, not their bounding spheres, and drive",
          "[flight_summary]") {
  // e-puck-like robots: an upright cylinder 7 cm wide, 5 cm high, its centre 3 cm above the root
  // (bounding sphere 7.3 cm from the root), on wheels
  Environment env;
  env.addGround();
  auto puck = [&](const std::string& name, double x, double y) {
    Artifact& a = env.addArtifact(name, at(x, y, 0.0));
    PhysicNodeSpec body;
    body.name = "body";
    body.mass = 0.2;
    Shape c = Shape::cylinder(0.035, 0.05);
    c.pose.position = Vec3(0, 0, 0.03);
    body.shapes.push_back(c);
    a.addPhysicRoot(std::move(body));
    a.setDriver(std::make_unique<Wheels>());
  };
  puck("near", 0, 0);
  puck("apart", 0.0925, 0);    // 9.25 cm centre to centre: 2.25 cm of air between them
  puck("touching", 0, 0.069);  // 6.9 cm: touching "near"
  FlightRecorder recorder;
  for (int k = 0; k < 20; ++k) {
    env.step(5);
    recorder.observe(env);
  }
  const FlightSummary s = recorder.summary();
  CHECK(s.wheeled == 3);
  CHECK(s.collisions == 1);
  CHECK(s.first_collision_pair == "near and touching");
  CHECK_THAT(s.str(), Catch::Contains("; mean distance driven "));
}
