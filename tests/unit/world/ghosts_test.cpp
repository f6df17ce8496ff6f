// Ghosts (ghosts.cpp): real robots inside the simulation, moved by the poses they are given. The
// pose used at each step is the interpolation of the samples received (or their extrapolation, as
// PoseStream gives it); a ghost whose samples stop is lost after its timeout, its sensors silent,
// and found again; its range sensor sees a virtual pillar, simulated robots see it and rest on it,
// nothing pushes it; runs are the same bits on any thread count and after save/restore.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

using namespace ssx;
using namespace ssx::test;
using Catch::Contains;

namespace {

std::string types() {
  return R"(<type name="dot" file=")" + (kData / "valid" / "dot.xml").string() + R"("/>
    <type name="ball" file=")" + (kData / "valid" / "ball.xml").string() + R"("/>
    <type name="box" file=")" + (kArtifacts / "box.xml").string() + R"("/>)";
}

Scene ghostScene(int threads = 1, const std::string& ghost = R"(<ghost timeout="0.1" horizon="0.02"/>)") {
  const std::string xml = R"(<scene><environment timestep="0.001" seed="3" threads=")" + std::to_string(threads) +
                          R"("/><physics gravity="0 0 0"/>)" + types() + R"(
    <obstacle name="pillar" xyz="2 0 0"><cylinder radius="0.2" length="3"/></obstacle>
    <artifact name="real" type="dot" xyz="0 0 1">)" + ghost + R"(</artifact>
    <artifact name="sim" type="dot" xyz="0 1 1"/>
  </scene>)";
  return loadSceneFromString(xml, "ghosts.xml", kArtifacts, testOptions());
}

// a motion-capture stream: every ~10 ms (jittered), a point on a 1 m circle at 1 rad/s, turning with it
struct Sample {
  double stamp;
  Pose pose;
};
std::vector<Sample> circle(double until) {
  std::vector<Sample> out;
  for (int k = 0; 0.01 * k <= until; ++k) {
    const double t = 0.01 * k + 0.002 * std::sin(7.0 * k);  // irregular
    Pose p;
    p.position = Vec3(std::cos(t), std::sin(t), 1.0);
    p.orientation = Quat(Eigen::AngleAxisd(t, Vec3::UnitZ()));
    out.push_back({t, p});
  }
  return out;
}

const RangeMeasurement& rangeOf(const Environment& env, const std::string& name) {
  return dynamic_cast<const RangeMeasurement&>(env.findArtifact(name)->sensor(0).latest());
}

}  // namespace

TEST_CASE("ghosts: the pose used at each step is the interpolation of the samples received", "[ghosts]") {
  Scene scene = ghostScene();
  Environment& env = *scene.environment;
  const Artifact& real = *env.findArtifact("real");
  CHECK(env.isGhost(real));
  CHECK_FALSE(env.isGhost(*env.findArtifact("sim")));
  const auto samples = circle(2.1);
  SECTION("samples received 50 ms ahead of their time (a replay): interpolated") {
    std::size_t next = 0;
    double worst = 0, worst_turn = 0;
    for (int k = 0; k < 2000; ++k) {
      for (; next < samples.size() && samples[next].stamp <= toSeconds(env.time()) + 0.05; ++next)
        env.setExternalPose("real", samples[next].pose, samples[next].stamp);
      env.step();
      const double t = toSeconds(env.time());
      // the two samples around t, interpolated here
      std::size_t b = 1;
      while (samples[b].stamp < t) ++b;
      const Sample& lo = samples[b - 1];
      const Sample& hi = samples[b];
      const double u = (t - lo.stamp) / (hi.stamp - lo.stamp);
      const Vec3 expected = lo.pose.position + u * (hi.pose.position - lo.pose.position);
      worst = std::max(worst, (real.pose().position - expected).norm());
      worst_turn = std::max(worst_turn, real.pose().orientation.angularDistance(
                                            lo.pose.orientation.slerp(u, hi.pose.orientation)));
    }
    CHECK(worst < 1e-3);  // the issue's bound; in fact rounding
    CHECK(worst < 1e-9);
    CHECK(worst_turn < 1e-9);
    // the body moved at the samples' speed: what the contacts and the IMU see
    CHECK(real.state().linear_velocity.norm() == Approx(1.0).epsilon(0.01));
    CHECK_FALSE(env.ghostStatus(real).lost);
  }
  SECTION("samples arriving 15 ms after their stamps: what a pose stream with them says") {
    PoseStream reference({0.02, 0.1, 64});
    std::size_t next = 0;
    double worst = 0;
    for (int k = 0; k < 2000; ++k) {
      const double now = toSeconds(env.time());
      for (; next < samples.size() && samples[next].stamp + 0.015 <= now; ++next) {
        env.setExternalPose("real", samples[next].pose, samples[next].stamp);
        reference.add(samples[next].stamp, samples[next].pose);
      }
      env.step();
      if (k < 30) continue;  // (lost until the first sample arrives)
      const auto e = reference.at(toSeconds(env.time()));
      REQUIRE(e);
      worst = std::max(worst, (real.pose().position - e->pose.position).norm());
    }
    CHECK(worst < 1e-9);
    // ages: 15 ms late plus up to a sample interval (~10 ms) since the newest
    const AgeSummary ages = env.ghostAges();
    CHECK(ages.count >= 1900);
    CHECK(ages.median == Approx(0.020).margin(0.003));
    CHECK(ages.p99 <= 0.029);
    CHECK(ages.p99 >= 0.024);
  }
}

TEST_CASE("ghosts: a ghost whose samples stop is lost after its timeout, its sensors silent, and found again",
          "[ghosts]") {
  Scene scene = ghostScene();
  Environment& env = *scene.environment;
  std::vector<std::string> log;
  env.setLogSink([&](LogLevel, std::string_view m) { log.emplace_back(m); });
  Artifact& real = *env.findArtifact("real");
  int measured = 0;
  env.subscribe(real.sensor(0), *env.findArtifact("sim"), [&](const Measurement&) { ++measured; });
  CHECK(env.ghostStatus(real).lost);  // no pose yet
  env.step(10);
  CHECK(measured == 0);  // lost from the start: silent
  Pose p;
  p.position = Vec3(0.5, 0, 1);
  for (int k = 0; k <= 50; ++k) env.setExternalPose("real", p, 0.01 * k);  // until t = 0.5 s
  env.step(490);                                                           // to t = 0.5 s
  CHECK_FALSE(env.ghostStatus(real).lost);
  CHECK(measured == 490);
  CHECK(real.pose().position.isApprox(p.position));
  env.step(99);  // t = 0.599 s: 0.099 s without a sample
  CHECK_FALSE(env.ghostStatus(real).lost);
  CHECK(measured == 589);
  env.step(2);  // t = 0.601 s: more than the timeout
  CHECK(env.ghostStatus(real).lost);
  CHECK(env.ghostStatus(real).age == Approx(0.101));
  CHECK(measured >= 589);  // (lost at 0.600 or 0.601 s: the timeout falls on a step, rounding decides)
  CHECK(measured <= 590);
  const int before = measured;
  REQUIRE(log.size() == 1);
  CHECK_THAT(log[0], Contains("ghost 'real' lost at t=0.60"));
  CHECK_THAT(log[0], Contains("s: no pose since t=0.500 s (timeout 0.100 s)"));
  env.step(100);
  CHECK(measured == before);  // silent
  CHECK(real.pose().position.isApprox(p.position));  // held where it was
  // found again: put at once where the new sample says (not swept there, and not extrapolated
  // from the sample before the gap)
  p.position = Vec3(0, -0.5, 1);
  env.setExternalPose("real", p, 0.7);
  env.step();
  CHECK_FALSE(env.ghostStatus(real).lost);
  CHECK(real.pose().position.isApprox(p.position));
  CHECK(real.state().linear_velocity.norm() == 0);
  CHECK(measured == before + 1);
  REQUIRE(log.size() == 2);
  CHECK_THAT(log[1], Contains("ghost 'real' tracked again at t=0.702 s"));
}

TEST_CASE("ghosts: a ghost's range sensor sees a virtual pillar, simulated robots see the ghost", "[ghosts]") {
  Scene scene = ghostScene();
  Environment& env = *scene.environment;
  Pose p;
  p.position = Vec3(0.5, 0, 1);
  env.setExternalPose("real", p, 0);
  env.step();
  // the pillar's surface 2 - 0.2 - 0.5 = 1.3 m ahead; the simulated dot at (0, 1, 1)
  const auto& seen = rangeOf(env, "real").detections;
  REQUIRE(seen.size() == 2);
  CHECK(env.artifact(seen[0].artifact).name() == "sim");
  CHECK(seen[0].distance == Approx(std::hypot(0.5, 1.0)));
  CHECK(env.artifact(seen[1].artifact).name() == "pillar");
  CHECK(seen[1].obstacle);
  CHECK(seen[1].distance == Approx(1.3));
  CHECK(seen[1].relative.isApprox(Vec3(1.3, 0, 0)));
  const auto& other = rangeOf(env, "sim").detections;
  REQUIRE_FALSE(other.empty());
  CHECK(env.artifact(other[0].artifact).name() == "real");
  CHECK(other[0].relative.isApprox(Vec3(0.5, -1, 0)));
}

TEST_CASE("ghosts: a simulated box rests on a rising ghost and is carried, nothing pushes the ghost", "[ghosts]") {
  const std::string engine = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(engine);
  const std::string xml = R"(<scene><environment timestep="0.002"/><physics engine=")" + engine + R"("/>)" + types() + R"(
    <artifact name="lift" type="box" xyz="0 0 0.5"><ghost timeout="1"/></artifact>
    <artifact name="load" type="box" xyz="0 0 0.75"/>
  </scene>)";
  Scene scene = loadSceneFromString(xml, "lift.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  Pose p;
  p.position = Vec3(0, 0, 0.5);
  env.setExternalPose("lift", p, 0);
  env.setExternalPose("lift", p, 0.5);  // still for 0.5 s: the load lands on it
  p.position.z() = 0.8;
  env.setExternalPose("lift", p, 1.5);  // then up 0.3 m in 1 s
  env.step(250);  // t = 0.5 s: landed on the lift's top
  CHECK(env.findArtifact("load")->pose().position.z() == Approx(0.7).margin(0.005));
  env.step(450);  // t = 1.4 s: risen 0.27 m, the load with it
  CHECK(env.findArtifact("lift")->pose().position.z() == Approx(0.77).margin(1e-9));
  CHECK(env.findArtifact("lift")->pose().position.x() == 0);
  CHECK(env.findArtifact("load")->pose().position.z() == Approx(0.97).margin(0.005));
  CHECK(env.findArtifact("load")->state().linear_velocity.z() == Approx(0.3).margin(0.03));
}

TEST_CASE("ghosts: the same samples give the same bits on any thread count and after save/restore",
          "[ghosts][state][bitwise]") {
  const auto samples = circle(1.0);
  auto run = [&](int threads, std::vector<std::byte>* save_at_500, const std::vector<std::byte>* restore) {
    Scene scene = ghostScene(threads);
    Environment& env = *scene.environment;
    std::size_t next = 0;
    for (int k = 0; k < 1000; ++k) {
      if (restore != nullptr && k == 0) {
        env.restoreState(*restore);
        k = 500;
        while (next < samples.size() && samples[next].stamp + 0.015 <= 0.5) ++next;
      }
      const double now = toSeconds(env.time());
      for (; next < samples.size() && samples[next].stamp + 0.015 <= now; ++next)
        env.setExternalPose("real", samples[next].pose, samples[next].stamp);
      if (k == 500 && save_at_500 != nullptr) *save_at_500 = env.saveState();
      env.step();
    }
    return env.stateHash();
  };
  std::vector<std::byte> saved;
  const std::uint64_t one = run(1, &saved, nullptr);
  CHECK(run(2, nullptr, nullptr) == one);
  CHECK(run(1, nullptr, &saved) == one);
}

TEST_CASE("ghosts: what cannot be a ghost is refused before anything runs, with where", "[ghosts]") {
  auto load = [](const std::string& body) {  // (the types are lines 1-3)
    return loadSceneFromString("<scene>" + types() + body + "</scene>", "bad.xml", kArtifacts, testOptions());
  };
  CHECK_THROWS_WITH(load(R"(<artifact name="a" type="dot">
      <ghost timeout="-1"/></artifact>)"),
                    Contains("bad.xml:4: error: <ghost>: attribute 'timeout' must be 0 s or more, got '-1'"));
  CHECK_THROWS_WITH(load(R"(<artifact name="a" type="ball"><driver kp="1"/>
      <ghost/></artifact>)"),
                    Contains("bad.xml:3: error: <driver>: 'a' is a ghost (moved by the poses it is given): it runs no driver"));
  CHECK_THROWS_WITH(load(R"(<artifact name="a" type="dot"><ghost capacity="1"/></artifact>)"),
                    Contains("attribute 'capacity' must be at least 2"));
  // a ghost of a type with a driver runs without it
  Scene s = load(R"(<swarm name="g{i}" type="ball" count="3"><ghost/></swarm>)");
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(s.environment->isGhost(s.environment->artifact(i)));
    CHECK(s.environment->artifact(i).driver() == nullptr);
  }
  // in code
  Environment env;
  Artifact& driven = *s.environment->findArtifact("g0");
  CHECK_THROWS_WITH(env.setGhost(driven), Contains("belongs to another environment"));
  Artifact& ground = env.addGround();
  CHECK_THROWS_WITH(env.setGhost(ground), Contains("artifact 'ground' cannot be a ghost: a ghost is one dynamic physic tree"));
  CHECK_THROWS_WITH(env.setExternalPose("ground", Pose{}, 0), Contains("'ground' is not a ghost (make it one with setGhost"));
  CHECK_THROWS_WITH(env.setExternalPose("nobody", Pose{}, 0), Contains("no artifact has that name"));
  Artifact& a = env.addArtifact("a");
  PhysicNodeSpec spec;
  spec.name = "body";
  spec.shapes.push_back(Shape::sphere(0.1));
  a.addPhysicRoot(spec);
  CHECK_THROWS_WITH(env.setGhost(a, {-1, 0.5, 64}), Contains("cannot be a ghost: pose stream: the extrapolation horizon"));
  env.setGhost(a);
  CHECK_THROWS_WITH(env.setGhost(a), Contains("it is one already"));
  Pose bad;
  bad.orientation.coeffs() *= 2;
  CHECK_THROWS_AS(env.setExternalPose("a", bad, 0), std::invalid_argument);
}
