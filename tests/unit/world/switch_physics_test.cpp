// Exchanging the physics engine while a run goes on (switch_physics.cpp, Environment::switchPhysics):
// a hovering swarm switched ODE -> Bullet -> ODE keeps hovering without a jump; a free flight
// continued on the other engine matches that engine's own run; a pendulum's swing, a held body and
// a ghost carry over; switching is the same bits on 1 and 2 threads and after save/restore (a
// state names its engine); nonsense is refused.
#include "scene_util.hpp"
#include "state_scene.hpp"
#include "test_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace ssx;
using Catch::Contains;
using ssx::test::kArtifacts;

namespace {

// nine mk_quads take off from the ground and hold 1 m above where they started
Scene hoverSwarm(int threads = 1) {
  return loadSceneFromString(
      "<scene><environment timestep=\"0.002\" seed=\"5\" threads=\"" + std::to_string(threads) +
          "\"/><type name=\"quad\" file=\"" + (kArtifacts / "mk_quad.xml").string() +
          "\"/><ground/><swarm type=\"quad\" count=\"9\" layout=\"grid\" spacing=\"1.5\" xyz=\"0 0 0.05\">"
          "<driver offset=\"0 0 1\"/></swarm></scene>",
      "hover.xml", kArtifacts);
}

std::vector<Vec3> positions(const Environment& env) {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < env.artifactCount(); ++i)
    if (env.artifact(i).name() != "ground") out.push_back(env.artifact(i).pose().position);
  return out;
}

double largestGap(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d;
}

}  // namespace

TEST_CASE("switching engines: a hovering swarm switched ODE -> Bullet -> ODE keeps hovering, without a jump",
          "[switch_physics]") {
  Scene switched = hoverSwarm();
  Scene plain = hoverSwarm();  // the same run on ODE throughout
  Environment& env = *switched.environment;
  Environment& ref = *plain.environment;
  const std::vector<Vec3> start = positions(env);
  env.step(1500);  // 3 s: up and holding
  ref.step(1500);
  for (const std::string engine : {"bullet", "ode"}) {
    INFO("to " << engine);
    const std::vector<Vec3> before = positions(env);
    const std::vector<Vec3> ref_before = positions(ref);
    env.switchPhysics(engine);
    CHECK(env.physics().name() == engine);
    CHECK(positions(env) == before);  // the snapshot is as it was
    env.step();
    ref.step();
    // the first step on the new engine moves each robot as the old engine's step does, to far
    // less than one step's motion (both integrate the same forces over a free flight)
    double step_motion = 0;
    for (std::size_t i = 0; i < before.size(); ++i)
      step_motion = std::max(step_motion, (positions(ref)[i] - ref_before[i]).norm());
    CHECK(step_motion > 0);
    CHECK(largestGap(positions(env), positions(ref)) < step_motion);
    env.step(500);  // 1 s on it
    ref.step(500);
  }
  // still hovering where they should: 1 m above their starts, as the run that never switched
  const std::vector<Vec3> end = positions(env);
  for (std::size_t i = 0; i < end.size(); ++i) CHECK((end[i] - (start[i] + Vec3(0, 0, 1))).norm() < 0.02);
  CHECK(largestGap(end, positions(ref)) < 1e-3);
  REQUIRE(env.physicsSwitches().size() == 2);
  CHECK(env.physicsSwitches()[0].time == toNanoseconds(3.0));
  CHECK(env.physicsSwitches()[0].from == "ode");
  CHECK(env.physicsSwitches()[0].to == "bullet");
  CHECK(env.physicsSwitches()[1].time == toNanoseconds(4.002));
  CHECK(env.settings().physics.engine == "ode");
}

TEST_CASE("switching engines: a free flight continued on the other engine matches that engine's run from the start",
          "[switch_physics]") {
  const std::string from = GENERATE(as<std::string>{}, "ode", "bullet");
  const std::string to = from == "ode" ? "bullet" : "ode";
  INFO(from << " -> " << to);
  Scene switched = hoverSwarm();
  Scene other = hoverSwarm();
  switched.environment->switchPhysics(from);  // before start: the engine the run starts with
  other.environment->switchPhysics(to);
  CHECK(switched.environment->physicsSwitches().empty());
  // take off on one engine (contacts with the ground until airborne), fly 2 s on the other
  switched.environment->step(250);
  other.environment->step(250);
  switched.environment->switchPhysics(to);
  switched.environment->step(1000);
  other.environment->step(1000);
  const double gap = largestGap(positions(*switched.environment), positions(*other.environment));
  INFO("largest gap after 2 s: " << gap << " m");
  CHECK(gap < 1e-6);
}

TEST_CASE("switching engines: the same switches give the same bits on 1 and 2 threads and after save/restore",
          "[switch_physics][state]") {
  // quadrotors fly a formation around a pillar while boxes fall on each other: contacts, noise
  auto run = [](int threads, std::vector<std::byte>* saved_on_bullet) {
    Scene scene = ssx::test::loadStateScene(threads);
    Environment& env = *scene.environment;
    env.switchPhysicsAt(toNanoseconds(0.4), "bullet");
    env.switchPhysicsAt(toNanoseconds(0.8), "ode");
    env.step(300);
    if (saved_on_bullet != nullptr) *saved_on_bullet = env.saveState();
    env.step(450);
    CHECK(env.physicsSwitches().size() == 2);
    return env.stateHash();
  };
  std::vector<std::byte> saved;
  const std::uint64_t one = run(1, &saved);
  CHECK(run(2, nullptr) == one);
  CHECK(run(1, nullptr) == one);
  // the state saved at 0.6 s (on Bullet) restored into the scene as loaded (ODE): it continues on
  // Bullet, and with the switch back asked for again, ends as the run that saved it
  Scene again = ssx::test::loadStateScene(2);
  again.environment->restoreState(saved);
  CHECK(again.environment->physics().name() == "bullet");
  again.environment->switchPhysicsAt(toNanoseconds(0.8), "ode");
  again.environment->step(450);
  CHECK(again.environment->stateHash() == one);
  // and differs from the run that never switched (the switches did something)
  Scene never = ssx::test::loadStateScene(1);
  never.environment->step(750);
  CHECK(never.environment->stateHash() != one);
}

TEST_CASE("switching engines: a swinging pendulum and a held body carry over", "[switch_physics][joints]") {
  const std::string from = GENERATE(as<std::string>{}, "ode", "bullet");
  const std::string to = from == "ode" ? "bullet" : "ode";
  INFO(from << " -> " << to);
  EnvironmentSettings s;
  s.physics.engine = from;
  s.timestep = toNanoseconds(0.001);
  auto build = [&](Environment& env) {
    PhysicNodeSpec base;
    base.name = "base";
    base.is_static = true;
    PhysicNodeSpec arm;
    arm.name = "arm";
    arm.pose.orientation = Quat(Eigen::AngleAxisd(1.0, Vec3::UnitY()));
    arm.joint.kind = JointSpec::Kind::Hinge;
    arm.joint.axis = Vec3::UnitY();
    arm.shapes.push_back(Shape::sphere(0.05, Pose{Vec3(0, 0, -1), Quat::Identity()}));
    arm.mass = 1.0;
    base.addChild(arm);
    env.addArtifact("pendulum", ssx::test::at(0, 0, 3)).addPhysicRoot(base);
    // a 5 cm cube held 20 cm beside a free-falling box
    env.addArtifact("holder", ssx::test::at(5, 0, 10)).addPhysicRoot(ssx::test::boxBody(Vec3(0.2, 0.2, 0.2), 1.0));
    env.addArtifact("item", ssx::test::at(5.2, 0, 10)).addPhysicRoot(ssx::test::boxBody(Vec3(0.05, 0.05, 0.05), 0.05));
  };
  Environment env(s);
  build(env);
  PhysicNode& arm = *env.findArtifact("pendulum")->node("arm");
  PhysicNode& holder = env.findArtifact("holder")->root();
  const PhysicNode& item = env.findArtifact("item")->root();
  env.start();
  holder.attach(item);
  holder.setVelocity(Vec3(0, 0, 0), Vec3(0, 0, 2.0));  // spinning while it falls
  env.step(300);
  const double angle = arm.jointPosition();
  const double rate = arm.jointVelocity();
  const Vec3 offset = holder.pose().inverse().transformPoint(item.pose().position);
  env.switchPhysics(to);
  CHECK(arm.jointPosition() == angle);
  CHECK(arm.jointVelocity() == rate);
  CHECK(holder.attachments() == 1);
  env.step();
  // the swing goes on from where it was: one step's motion, not a jump back to the scene's pose
  CHECK(std::abs(arm.jointPosition() - angle) < 2 * std::abs(rate) * 0.001 + 1e-6);
  double lowest = 1e9, highest = -1e9;
  for (int k = 0; k < 2500; ++k) {
    env.step();
    lowest = std::min(lowest, arm.jointPosition());
    highest = std::max(highest, arm.jointPosition());
  }
  // energy kept: it swings 1 rad out on both sides of hanging straight down (the joint's 0 is the
  // pose it was placed in, 1 rad out: hanging is -1)
  CHECK(highest == Approx(0.0).margin(0.02));
  CHECK(lowest == Approx(-2.0).margin(0.02));
  // the held cube is still held where it was in the holder's frame
  CHECK(holder.attachments() == 1);
  CHECK((holder.pose().inverse().transformPoint(item.pose().position) - offset).norm() < 1e-3);
}

TEST_CASE("switching engines: unknown engines, the wrong moment and a failed world are refused", "[switch_physics]") {
  Scene scene = hoverSwarm();
  Environment& env = *scene.environment;
  CHECK_THROWS_WITH(env.switchPhysics("mujoco"), Contains("unknown physics engine 'mujoco' (available: ode, bullet)"));
  CHECK_THROWS_WITH(env.switchPhysicsAt(1, "physx"), Contains("unknown physics engine 'physx'"));
  CHECK_THROWS_WITH(env.switchPhysicsAt(-1, "bullet"), Contains("negative time"));
  env.step(10);
  env.switchPhysics("ode");  // the engine already stepping: nothing happens
  CHECK(env.physicsSwitches().empty());
  env.stop();
  CHECK_THROWS_WITH(env.switchPhysics("bullet"), Contains("failed or was stopped"));

  // from a driver (the parallel phases): refused, and the step fails as for any plugin error
  Environment inside;
  Environment* at = &inside;
  ssx::test::addBall(inside, "ball").setDriver(std::make_unique<ssx::test::LambdaDriver>(
      [at](Driver&, const StepInfo&) { at->switchPhysics("bullet"); }));
  CHECK_THROWS_WITH(inside.step(), Contains("switchPhysics is not allowed from a driver"));
}
