// Joints made and broken at run time (attachments.cpp, PhysicNode::attach / release / detach), on
// ODE and Bullet: a held body keeps its place in the holder's frame while the holder is pushed and
// turned, and stays behind once let go; a driver's request takes effect as its drivers phase ends
// (before an extension could move the body), the program's at once; the same bits on 1 and 2
// threads and after save/restore; nonsense refused.
#include "test_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <memory>
#include <string>
#include <vector>

using namespace ssx;
using Catch::Contains;
using ssx::test::LambdaDriver;

namespace {

constexpr int kPairs = 40;  // 80 bodies: more than one ODE partition holds (64)
constexpr std::int64_t kGrab = 100, kLetGo = 400;

EnvironmentSettings settings(const std::string& engine, int threads) {
  EnvironmentSettings s;
  s.physics.engine = engine;
  s.physics.gravity = Vec3::Zero();
  s.timestep = toNanoseconds(0.002);
  s.threads = threads;
  return s;
}

// what each gripper's driver saw of its own attachments, per step
struct Seen {
  std::vector<std::size_t> attachments;
};

// grippers (all first) and an item 5 cm ahead of each; each gripper's driver takes its item at
// step kGrab, pushes it forward while turning, lets go at kLetGo and backs away
std::unique_ptr<Environment> build(const std::string& engine, int threads, Seen* seen = nullptr) {
  auto env = std::make_unique<Environment>(settings(engine, threads));
  std::vector<Artifact*> grippers;
  for (int i = 0; i < kPairs; ++i)
    grippers.push_back(&env->addArtifact("gripper" + std::to_string(i), ssx::test::at(0, i, 0)));
  for (int i = 0; i < kPairs; ++i) {
    grippers[static_cast<std::size_t>(i)]->addPhysicRoot(ssx::test::boxBody(Vec3(0.2, 0.2, 0.2), 1.0));
    Artifact& item = env->addArtifact("item" + std::to_string(i), ssx::test::at(0.175, i, 0));
    item.addPhysicRoot(ssx::test::boxBody(Vec3(0.05, 0.05, 0.05), 0.05));
    PhysicNode* hand = &grippers[static_cast<std::size_t>(i)]->root();
    const PhysicNode* held = &item.root();
    grippers[static_cast<std::size_t>(i)]->setDriver(
        std::make_unique<LambdaDriver>([hand, held, seen, i](Driver&, const StepInfo& info) {
          if (seen != nullptr && i == 0) seen->attachments.push_back(hand->attachments());
          if (info.step == kGrab) hand->attach(*held);
          if (info.step == kLetGo) hand->release();
          const double push = info.step < kLetGo ? 1.0 : -1.0;
          hand->addForce(Vec3(push, 0, 0), Frame::Local);
          if (info.step < kLetGo) hand->addTorque(Vec3(0, 0, 0.05 * (1 + i % 3)));
        }));
  }
  return env;
}

}  // namespace

TEST_CASE("attachments: a held body keeps its place in the holder's frame, and stays behind once let go",
          "[attachments][joints]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  Seen seen;
  auto env = build(engine, 1, &seen);
  const PhysicNode& hand = env->findArtifact("gripper7")->root();
  const PhysicNode& item = env->findArtifact("item7")->root();
  env->step(kGrab);
  CHECK(hand.attachments() == 0);
  env->step();  // the request is made in step kGrab and carried out as its drivers phase ends
  CHECK(hand.attachments() == 1);
  CHECK(item.attachments() == 1);
  const Vec3 offset = hand.pose().inverse().transformPoint(item.pose().position);  // as the joint holds it
  CHECK(offset.x() > 0.1);
  double worst = 0;
  for (std::int64_t s = kGrab + 1; s < kLetGo; ++s) {
    env->step();
    worst = std::max(worst, (hand.pose().inverse().transformPoint(item.pose().position) - offset).norm());
  }
  CHECK(worst < 1e-3);  // held: the item goes where the gripper goes, turning with it
  CHECK(hand.state().angular_velocity.z() > 0.1);  // (it did turn)
  CHECK(hand.pose().position.x() > 0.2);            // and move
  env->step();  // let go at kLetGo; backs away from then on
  CHECK(hand.attachments() == 0);
  CHECK(item.attachments() == 0);
  const double gap = (hand.pose().position - item.pose().position).norm();
  env->step(300);
  CHECK((hand.pose().position - item.pose().position).norm() > gap + 0.05);
  // the driver saw its request counted from the step after it asked
  REQUIRE(seen.attachments.size() > static_cast<std::size_t>(kLetGo + 1));
  CHECK(seen.attachments[kGrab] == 0);
  CHECK(seen.attachments[kGrab + 1] == 1);
  CHECK(seen.attachments[kLetGo] == 1);
  CHECK(seen.attachments[kLetGo + 1] == 0);
}

TEST_CASE("attachments: the same bits on 1 and 2 threads and after save/restore, saved just after the joints were made",
          "[attachments][joints][determinism]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  auto one = build(engine, 1);
  one->step(kGrab + 1);  // the drivers of step kGrab asked: the joints are made, not stepped yet
  CHECK(one->findArtifact("gripper0")->root().attachments() == 1);
  const auto pending = one->saveState();
  one->step(200);
  const auto held = one->saveState();
  one->step(300);  // past kLetGo: the joints removed again
  const std::uint64_t expected = one->stateHash();
  auto two = build(engine, 2);
  two->step(kGrab + 501);
  CHECK(two->stateHash() == expected);
  for (const auto* state : {&pending, &held}) {
    auto restored = build(engine, 2);
    restored->step(3);
    restored->restoreState(*state);
    restored->step(kGrab + 501 - restored->stepCount());
    CHECK(restored->stateHash() == expected);
  }
  // restored into a world that has joints of its own made since: they go
  auto late = build(engine, 1);
  late->step(kLetGo + 10);
  CHECK(late->findArtifact("gripper0")->root().attachments() == 0);
  late->restoreState(held);
  CHECK(late->findArtifact("gripper0")->root().attachments() == 1);
  late->restoreState(pending);
  late->findArtifact("gripper5")->root().detach();  // (changes nothing the run would: restored again below)
  CHECK(late->findArtifact("gripper5")->root().attachments() == 0);
  late->restoreState(pending);
  CHECK(late->findArtifact("gripper5")->root().attachments() == 1);
  late->step(kGrab + 501 - late->stepCount());
  CHECK(late->stateHash() == expected);
}

TEST_CASE("attachments: between steps the program's requests take effect at once, nonsense is refused",
          "[attachments][joints]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  Environment env(settings(engine, 1));
  Artifact& a = env.addArtifact("a", ssx::test::at(0, 0, 0));
  a.addPhysicRoot(ssx::test::boxBody(Vec3(0.2, 0.2, 0.2), 1.0));
  Artifact& b = env.addArtifact("b", ssx::test::at(0.3, 0, 0));
  b.addPhysicRoot(ssx::test::boxBody(Vec3(0.2, 0.2, 0.2), 1.0));
  Artifact& wall = env.addArtifact("wall", ssx::test::at(0, 2, 0));
  PhysicNodeSpec w = ssx::test::boxBody(Vec3(1, 0.1, 1), 1.0);
  w.is_static = true;
  wall.addPhysicRoot(w);
  PhysicNode& na = a.root();
  PhysicNode& nb = b.root();
  CHECK_THROWS_WITH(na.attach(nb), Contains("once the environment has started"));
  env.start();
  CHECK_THROWS_WITH(na.attach(na), Contains("same body"));
  CHECK_THROWS_WITH(wall.root().attach(na), Contains("static node cannot hold"));
  na.attach(nb);
  CHECK(na.attachments() == 1);
  na.attach(nb);  // already joined: nothing more
  nb.attach(na);
  CHECK(nb.attachments() == 1);
  // pushed apart, they stay together
  nb.setVelocity(Vec3(1, 0, 0), Vec3::Zero());
  env.step(100);
  CHECK((nb.pose().position - na.pose().position).norm() == Approx(0.3).margin(1e-3));
  // taken out of the hold and moved: it stays where it was put
  nb.detach();
  CHECK(na.attachments() == 0);
  BodyState moved = env.bodyState(nb.bodyIndex());
  moved.pose.position += Vec3(0, -1, 0);
  moved.linear_velocity = Vec3::Zero();
  env.setBodyState(nb.bodyIndex(), moved);
  env.step(50);
  CHECK((nb.pose().position - moved.pose.position).norm() < 1e-9);
  // held by the static wall, a body does not move however it is pushed
  na.attach(wall.root());
  const Vec3 before = na.pose().position;
  na.setVelocity(Vec3(0, 0, 1), Vec3::Zero());
  env.step(100);
  CHECK((na.pose().position - before).norm() < 5e-3);
  CHECK(na.state().linear_velocity.norm() < 1e-3);
}

TEST_CASE("attachments: held by a ball joint, a body hangs from the holder's node origin and swings about it",
          "[attachments][joints]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  EnvironmentSettings s = settings(engine, 1);
  s.physics.gravity = Vec3(0, 0, -9.81);
  Environment env(s);
  // a hook held in place by the static world, a 0.5 m bar beside it whose end is at the hook's origin
  Artifact& post = env.addArtifact("post", ssx::test::at(0, 0, 2));
  PhysicNodeSpec p = ssx::test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0);
  p.is_static = true;
  post.addPhysicRoot(p);
  Artifact& hook = env.addArtifact("hook", ssx::test::at(0, 0, 1));
  hook.addPhysicRoot(ssx::test::boxBody(Vec3(0.05, 0.05, 0.05), 1.0));
  Artifact& bar = env.addArtifact("bar", ssx::test::at(0.25, 0, 1));
  bar.addPhysicRoot(ssx::test::boxBody(Vec3(0.5, 0.02, 0.02), 0.1));
  Artifact& fixed = env.addArtifact("fixed", ssx::test::at(0, 3, 1));
  fixed.addPhysicRoot(ssx::test::boxBody(Vec3(0.05, 0.05, 0.05), 1.0));
  Artifact& beam = env.addArtifact("beam", ssx::test::at(0.25, 3, 1));
  beam.addPhysicRoot(ssx::test::boxBody(Vec3(0.5, 0.02, 0.02), 0.1));
  env.start();
  CHECK_THROWS_WITH(hook.root().attach(bar.root(), JointSpec::Kind::Hinge), Contains("fixed or a ball joint"));
  hook.root().attach(post.root());  // the hook and the other holder stay where they are
  fixed.root().attach(post.root());
  hook.root().attach(bar.root(), JointSpec::Kind::Ball);
  fixed.root().attach(beam.root());  // fixed: stays level
  double lowest = 1, worst = 0;
  for (int k = 0; k < 500; ++k) {  // 1 s: a quarter swing of a 0.5 m bar takes about 0.35 s
    env.step();
    // the bar's end stays at the hook's origin
    const Vec3 end = bar.root().pose().transformPoint(Vec3(-0.25, 0, 0));
    worst = std::max(worst, (end - hook.root().pose().position).norm());
    lowest = std::min(lowest, bar.root().pose().position.z());
  }
  INFO("the bar's end within " << worst * 1e3 << " mm of the hook; its centre down to z " << lowest);
  CHECK(worst < 2e-3);
  CHECK(lowest < 1 - 0.24);  // it swung down to hang below the hook
  CHECK((beam.root().pose().position - Vec3(0.25, 3, 1)).norm() < 5e-3);
}
