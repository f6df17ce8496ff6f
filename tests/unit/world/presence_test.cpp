// Artifacts taken out of the world and put back (presence.cpp: Environment::despawn and spawn,
// present="false" in a scene), on both engines: out of the world an artifact stays where it is,
// touches nothing, meets no ray, is found by no neighbour query and runs no plugin; spawned, it
// starts at rest where it was asked to and moves again; runs are the same bits on any thread
// count and after save/restore.
#include "scene_util.hpp"
#include "state_scene.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

using namespace ssx;
using namespace ssx::test;
using Catch::Contains;

namespace {

Scene reserveScene(const std::string& engine) {
  const std::string xml = R"(<scene><environment timestep="0.002" seed="5"/><physics engine=")" + engine + R"("/>
    <type name="box" file=")" +
                          (kArtifacts / "box.xml").string() + R"("/>
    <type name="quad" file=")" +
                          (kArtifacts / "mk_quad_formation.xml").string() + R"("/>
    <ground/>
    <obstacle name="pillar" xyz="5 0 1"><cylinder radius="0.2" length="2"/></obstacle>
    <artifact name="reserve" type="box" xyz="0 0 0.5" present="false"/>
    <artifact name="faller" type="box" xyz="0 0 2"/>
    <artifact name="quad" type="quad" xyz="3 0 0.05" present="false">
      <driver formation_index="0" formation_size="1" formation_radius="0.5" formation_center="3 0 1.5" start_time="0"/>
    </artifact>
  </scene>)";
  return loadSceneFromString(xml, "reserve.xml", kArtifacts, testOptions());
}

bool rayHits(const Environment& env, const Vec3& from, const Vec3& to) {
  const Ray ray{from, to};
  RayHit hit;
  env.castRays({&ray, 1}, {&hit, 1});
  return hit.hit;
}

}  // namespace

TEST_CASE(
    "an artifact out of the world stays put and touches nothing and meets no ray and runs no plugin until spawned",
    "[presence]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  Scene scene = reserveScene(engine);
  Environment& env = *scene.environment;
  env.enableNeighborQueries(1.0);
  env.enableRayQueries();
  env.start();
  Artifact& reserve = *env.findArtifact("reserve");
  Artifact& quad = *env.findArtifact("quad");
  const Artifact& faller = *env.findArtifact("faller");
  CHECK_FALSE(reserve.present());
  CHECK_FALSE(quad.present());
  CHECK(faller.present());
  const Pose reserve_start = reserve.root().pose();
  const Pose quad_start = quad.root().pose();
  env.step(1000);  // 2 s
  // held where it was, bit for bit, with gravity on; the box above fell through its place
  CHECK(reserve.root().pose().position == reserve_start.position);
  CHECK(quad.root().pose().position == quad_start.position);  // its controller would have taken off
  CHECK(faller.root().pose().position.z() < 0.15);
  // no ray meets it, no neighbour query finds it
  CHECK_FALSE(rayHits(env, Vec3(-1, 0, 0.5), Vec3(1, 0, 0.5)));
  std::vector<std::size_t> near;
  env.neighbors(Vec3(0, 0, 0.5), 0.3, near);
  CHECK(near.empty());

  // spawned: at rest where asked, then it falls onto the ground; found by rays and queries
  const Pose asked{Vec3(0, 0, 0.5), Quat(Eigen::AngleAxisd(0.5, Vec3::UnitZ()))};
  env.spawn(reserve, asked);
  CHECK(reserve.present());
  CHECK((reserve.root().pose().position - asked.position).norm() < 1e-12);
  CHECK(reserve.root().pose().orientation.angularDistance(asked.orientation) < 1e-12);
  CHECK(reserve.root().state().linear_velocity.norm() == 0.0);
  CHECK(rayHits(env, Vec3(-1, 0, 0.5), Vec3(1, 0, 0.5)));
  env.neighbors(Vec3(0, 0, 0.5), 0.3, near);
  CHECK(near == std::vector<std::size_t>{reserve.index()});
  env.spawn(quad, Pose{Vec3(3, 0, 0.05), Quat::Identity()});
  env.step(1000);
  CHECK(reserve.root().pose().position.z() < 0.5 - 0.1);  // it fell onto the box below or the ground
  CHECK(reserve.root().pose().position.z() > 0.05);
  CHECK(quad.root().pose().position.z() > 0.5);  // its driver flies it to 1.5 m

  // taken out again: it holds where it is from then on
  env.despawn(quad);
  const Pose held = quad.root().pose();
  env.step(200);
  CHECK(quad.root().pose().position == held.position);
  CHECK_FALSE(quad.present());
}

TEST_CASE("despawn and spawn refuse what they cannot do before anything changes", "[presence]") {
  Scene scene = reserveScene("ode");
  Environment& env = *scene.environment;
  Artifact& reserve = *env.findArtifact("reserve");
  Artifact& faller = *env.findArtifact("faller");
  CHECK_THROWS_WITH(env.spawn(reserve, Pose{}), Contains("not running"));
  env.start();
  CHECK_THROWS_WITH(env.despawn(*env.findArtifact("pillar")), Contains("fixed in the world"));
  CHECK_THROWS_WITH(env.despawn(reserve), Contains("out of the world already"));
  CHECK_THROWS_WITH(env.spawn(faller, Pose{}), Contains("in the world already"));
  Pose bad;
  bad.position.x() = std::nan("");
  CHECK_THROWS_WITH(env.spawn(reserve, bad), Contains("not finite"));
  CHECK_FALSE(reserve.present());
  CHECK(faller.present());
}

TEST_CASE("a scene's present attribute is read and a ghost cannot start out of the world", "[presence]") {
  const std::string types = R"(<type name="box" file=")" + (kArtifacts / "box.xml").string() + R"("/>)";
  CHECK_THROWS_WITH(
      loadSceneFromString("<scene>" + types + R"(<artifact name="a" type="box" present="maybe"/></scene>)",
                          "present.xml", kArtifacts, testOptions()),
      Contains("present.xml:1"));
  CHECK_THROWS_WITH(
      loadSceneFromString(
          "<scene>" + types + R"(<artifact name="a" type="box" present="false"><ghost/></artifact></scene>)",
          "ghost.xml", kArtifacts, testOptions()),
      Contains("is a ghost"));
  Scene scene = loadSceneFromString(
      "<scene>" + types + R"(<swarm type="box" count="3" spacing="1" xyz="0 0 1" present="false"/></scene>)",
      "swarm.xml", kArtifacts, testOptions());
  for (std::size_t i = 0; i < scene.environment->artifactCount(); ++i)
    CHECK_FALSE(scene.environment->artifact(i).present());
}

TEST_CASE("artifacts taken out and put back give the same bits on 1 2 and 4 threads and after a restore",
          "[presence][state]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  auto run = [&](int threads, std::uint64_t* after_restore) {
    Scene scene = loadStateScene(threads, "", engine);
    Environment& env = *scene.environment;
    env.step(100);
    Artifact& quad = env.artifact(3);
    Artifact& box = *env.findArtifact("box2");
    env.despawn(quad);
    env.despawn(box);
    env.step(100);
    const std::vector<std::byte> saved = env.saveState();
    auto go_on = [&] {
      env.spawn(quad, Pose{Vec3(0, 0, 3), Quat::Identity()});
      env.step(100);
      env.spawn(box, Pose{Vec3(4.3, 0, 3), Quat::Identity()});
      env.step(100);
      return env.stateHash();
    };
    const std::uint64_t hash = go_on();
    if (after_restore != nullptr) {
      env.restoreState(saved);
      CHECK_FALSE(quad.present());
      CHECK_FALSE(box.present());
      *after_restore = go_on();
    }
    return hash;
  };
  std::uint64_t restored = 0;
  const std::uint64_t one = run(1, &restored);
  CHECK(restored == one);
  CHECK(run(2, nullptr) == one);
  CHECK(run(4, nullptr) == one);
}
