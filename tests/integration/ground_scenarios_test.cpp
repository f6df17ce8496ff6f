// Ground-robot scenarios (examples/ground): each scene runs to its end and does what it is for.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <iterator>
#include <set>

using namespace ssx;
using namespace ssx::test;

namespace {

const std::filesystem::path kGround = std::filesystem::path(SSX_EXAMPLES_DIR) / "ground";

Scene groundExample(const std::string& file, std::vector<AttributeOverride> overrides = {}) {
  SceneOptions options = testOptions();
  options.overrides = std::move(overrides);
  return loadScene(kGround / file, options);
}

}  // namespace

TEST_CASE("ground scenarios: diffusion: 1,000 e-pucks spread from a packed square over the arena in 60 s",
          "[scenario][diffusion]") {
  Scene scene = groundExample("diffusion.xml");
  Environment& env = *scene.environment;
  // the arena's 0.25 m cells (40 x 40) that have had an e-puck in them, and how many hold one now
  constexpr double kCell = 0.25;
  std::set<std::pair<int, int>> visited;
  auto occupied = [&] {
    std::set<std::pair<int, int>> now;
    for (std::size_t i = 0; i < env.artifactCount(); ++i) {
      const Artifact& a = std::as_const(env).artifact(i);
      if (a.rootCount() == 0 || a.root().isStatic()) continue;
      const Vec3 p = a.root().pose().position;
      now.insert({static_cast<int>(std::floor((p.x() + 5) / kCell)), static_cast<int>(std::floor((p.y() + 5) / kCell))});
    }
    visited.insert(now.begin(), now.end());
    return now.size();
  };
  // how far they are from their centroid, root mean square (packed: 2.5 m; spread evenly over the
  // arena: 4.1 m)
  auto dispersion = [&] {
    std::vector<Vec3> p;
    Vec3 c = Vec3::Zero();
    for (std::size_t i = 0; i < env.artifactCount(); ++i) {
      const Artifact& a = std::as_const(env).artifact(i);
      if (a.rootCount() == 0 || a.root().isStatic()) continue;
      p.push_back(a.root().pose().position);
      c += p.back();
    }
    c /= static_cast<double>(p.size());
    double sum = 0;
    for (const Vec3& q : p) sum += (q - c).head<2>().squaredNorm();
    return std::sqrt(sum / static_cast<double>(p.size()));
  };
  const double packed = dispersion();
  const double start = static_cast<double>(occupied()) / 1600;
  for (int s = 0; s < 60; ++s) {
    env.step(50);
    (void)occupied();
  }
  const double spread = static_cast<double>(occupied()) / 1600;
  const double spread_rms = dispersion();
  const double coverage = static_cast<double>(visited.size()) / 1600;
  INFO("cells held at the start " << start * 100 << " %, after 60 s " << spread * 100 << " %; visited " << coverage * 100
                                  << " %; rms distance from the centroid " << packed << " m, after 60 s " << spread_rms << " m");
  CHECK(start < 0.42);     // 25 x 25 of the 40 x 40 cells (and the rows the grid's edges straddle)
  CHECK(coverage > 0.95);  // nearly every cell of the arena was reached
  CHECK(spread_rms > packed + 0.8);  // and they spread out
  // every e-puck is inside the arena, upright, on the floor
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    const Artifact& a = std::as_const(env).artifact(i);
    if (a.rootCount() == 0 || a.root().isStatic()) continue;
    const Pose p = a.root().pose();
    CHECK((std::abs(p.position.x()) < 5 && std::abs(p.position.y()) < 5));
    CHECK(std::abs(p.position.z()) < 0.002);
  }
}

TEST_CASE("ground scenarios: aggregation: BEECLUST gathers 60 e-pucks on the dark spot in 3 minutes, robots that "
          "never wait do not gather", "[scenario][aggregation]") {
  // the scene as written, and the same robots told never to wait (a control run)
  std::ifstream file(kGround / "aggregation.xml");
  const std::string xml((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  REQUIRE(xml.find(R"(wait_max="60")") != std::string::npos);
  auto onSpot = [&](const std::string& text) {
    Scene scene = loadSceneFromString(text, "aggregation.xml", kGround, testOptions());
    Environment& env = *scene.environment;
    env.step(9000);  // 180 s
    int on = 0, all = 0;
    for (std::size_t i = 0; i < env.artifactCount(); ++i) {
      const Artifact& a = std::as_const(env).artifact(i);
      if (a.driver() == nullptr) continue;
      ++all;
      const Vec3 p = a.root().pose().position;
      if (std::hypot(p.x() - 0.7, p.y() - 0.7) < 0.45 + 0.035) ++on;
    }
    return static_cast<double>(on) / all;
  };
  const double gathered = onSpot(xml);
  std::string never = xml;
  never.replace(never.find(R"(wait_max="60")"), 13, R"(wait_max="0" )");
  const double control = onSpot(never);
  INFO("on the dark spot after 180 s: " << gathered * 100 << " %; never waiting: " << control * 100
                                        << " % (the spot is 7 % of the arena)");
  CHECK(gathered > 0.4);
  CHECK(control < 0.2);
}

TEST_CASE("ground scenarios: foraging: 16 e-pucks carry items to the nest, each held by a fixed joint, robots "
          "that do not carry deliver next to none", "[scenario][foraging]") {
  std::ifstream file(kGround / "foraging.xml");
  const std::string xml((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  REQUIRE(xml.find(R"(controller="foraging")") != std::string::npos);
  struct Outcome {
    double delivered = 0;
    std::size_t most_held = 0;  // items held at once, at most
    double farthest = 0;        // m, from a held item to the nearest robot
  };
  auto run = [&](const std::string& text) {
    Scene scene = loadSceneFromString(text, "foraging.xml", kGround, testOptions());
    Environment& env = *scene.environment;
    Outcome out;
    for (int k = 0; k < 180; ++k) {  // 180 s, looked at every second
      env.step(50);
      std::vector<Vec3> robots, held;
      for (std::size_t i = 0; i < env.artifactCount(); ++i) {
        const Artifact& a = std::as_const(env).artifact(i);
        if (a.name().starts_with("epuck")) robots.push_back(a.root().pose().position);
        if (a.name().starts_with("item") && a.root().attachments() > 0) held.push_back(a.root().pose().position);
      }
      out.most_held = std::max(out.most_held, held.size());
      for (const Vec3& p : held) {
        double nearest = 1e9;
        for (const Vec3& r : robots) nearest = std::min(nearest, (p - r).head<2>().norm());
        out.farthest = std::max(out.farthest, nearest);
      }
    }
    const auto* counter = dynamic_cast<const MetricSource*>(env.extension("foraging"));
    REQUIRE(counter != nullptr);
    std::vector<Metric> m;
    counter->metrics(m);
    REQUIRE(m.size() == 2);
    CHECK(m[0].name == "items_delivered");
    out.delivered = m[0].value;
    CHECK(m[1].value == Approx(out.delivered / 3.0));  // per minute
    return out;
  };
  const Outcome foraging = run(xml);
  std::string wander = xml;
  wander.replace(wander.find(R"(controller="foraging")"), 21, R"(controller="diffusion")");
  const Outcome control = run(wander);
  INFO("items delivered in 180 s: " << foraging.delivered << " (most held at once: " << foraging.most_held
                                     << "); wandering robots that push items about: " << control.delivered);
  CHECK(foraging.delivered >= 15);  // at least 5 per minute
  CHECK(foraging.most_held >= 4);
  // a held item stays where its robot took it: touching the robot's front (3.5 + 1.5 cm apart
  // when touching; taken within 7 cm)
  CHECK(foraging.farthest < 0.075);
  CHECK(control.most_held == 0);
  CHECK(control.delivered <= 2);
}

TEST_CASE("ground scenarios: landing: a Crazyflie follows a TurtleBot3 Burger driving a circle, lands on its deck "
          "and rides on it with its motors stopped", "[scenario][landing]") {
  Scene scene = groundExample("landing.xml");
  Environment& env = *scene.environment;
  const Artifact& burger = *std::as_const(env).findArtifact("burger");
  const Artifact& cf = *std::as_const(env).findArtifact("cf");
  env.start();  // (the driver knows its reference once configured)
  const auto* landed = dynamic_cast<const MetricSource*>(cf.driver());
  REQUIRE(landed != nullptr);
  REQUIRE(landed->metricNames() == std::vector<std::string>{"landed"});
  auto isLanded = [&] {
    std::vector<Metric> m;
    landed->metrics(m);
    return m.at(0).value == 1.0;
  };
  // the quadrotor's origin relative to where it rests on the deck, in the world frame
  auto fromDeck = [&] { return Vec3(cf.root().pose().position - burger.root().pose().transformPoint(Vec3(-0.032, 0, 0.195))); };
  double worst_follow = 0, worst_ride = 0, first_landed = -1;
  Vec3 landed_at = Vec3::Zero();
  FlightRecorder recorder;
  for (int k = 1; k <= 300; ++k) {  // 30 s, looked at every 0.1 s
    env.step(50);
    recorder.observe(env);
    const double t = 0.1 * k;
    const Vec3 d = fromDeck();
    if (t >= 3 && t < 8) {  // following 0.4 m above the deck
      worst_follow = std::max(worst_follow, d.head<2>().norm());
      CHECK(d.z() == Approx(0.4).margin(0.1));  // (the crazyflie's PID climbs past it and settles slowly: 0.49 m at 3 s, 0.41 m at 8 s)
      CHECK(!isLanded());
    }
    if (first_landed < 0 && isLanded()) {
      first_landed = t;
      landed_at = burger.root().pose().position;
    }
    if (t >= 12) {  // down on the deck, riding
      CHECK(isLanded());
      worst_ride = std::max(worst_ride, std::max(d.head<2>().norm(), std::abs(d.z())));
    }
  }
  INFO("following: within " << worst_follow * 1e3 << " mm; landed at " << first_landed << " s; riding: within "
                            << worst_ride * 1e3 << " mm of the deck point");
  CHECK(worst_follow < 0.02);
  CHECK(first_landed > 8);
  CHECK(first_landed < 11);  // 0.4 m at 0.2 m/s, and settling
  CHECK(worst_ride < 0.015);
  // the Burger carried it along its circle (1 m radius at 0.1 m/s: 1.8 m of arc in 18 s)
  CHECK((burger.root().pose().position - landed_at).norm() > 1.2);
  // the run's summary: the Burger on its wheels, the Crazyflie landed (on the Burger's deck, 0.2 m up)
  const FlightSummary summary = recorder.summary();
  CHECK(summary.on_wheels == 1);
  CHECK(summary.landed == 1);
  CHECK(summary.airborne == 0);
}

TEST_CASE("ground scenarios: carry: a Crazyflie and a TurtleBot3 Burger carry a rod together, each holding an end by "
          "a ball joint", "[scenario][carry]") {
  Scene scene = groundExample("carry.xml");
  Environment& env = *scene.environment;
  const Artifact& burger = *std::as_const(env).findArtifact("burger");
  const Artifact& cf = *std::as_const(env).findArtifact("cf");
  const Artifact& rod = *std::as_const(env).findArtifact("rod");
  const Vec3 deck(-0.032, 0, 0.21);  // the Burger's hold_node, in its frame
  const Vec3 start = rod.root().pose().position;
  // where each anchor lies in the rod's frame: the holds keep these points there
  const Vec3 near_end = rod.root().pose().inverse().transformPoint(burger.root().pose().transformPoint(deck));
  const Vec3 far_end = rod.root().pose().inverse().transformPoint(cf.root().pose().position);
  double worst_joint = 0, worst_follow = 0, lowest = 1, highest = 0, least_up = 1;
  FlightRecorder recorder;
  for (int k = 1; k <= 300; ++k) {  // 30 s, looked at every 0.1 s
    env.step(50);
    recorder.observe(env);
    CHECK(rod.root().attachments() == 2);
    const Pose r = rod.root().pose();
    worst_joint = std::max({worst_joint, (r.transformPoint(near_end) - burger.root().pose().transformPoint(deck)).norm(),
                            (r.transformPoint(far_end) - cf.root().pose().position).norm()});
    if (0.1 * k >= 3) {  // settled: the Crazyflie at its point behind the Burger, the rod level
      const Vec3 point = burger.root().pose().transformPoint(Vec3(-0.462, 0, 0.21));
      worst_follow = std::max(worst_follow, (cf.root().pose().position - point).norm());
      lowest = std::min(lowest, r.position.z());
      highest = std::max(highest, r.position.z());
    }
    least_up = std::min(least_up, (cf.root().pose().orientation * Vec3::UnitZ()).z());
  }
  INFO("joints within " << worst_joint * 1e3 << " mm; the Crazyflie within " << worst_follow * 1e3
                        << " mm of its point; the rod's middle between z " << lowest << " and " << highest);
  CHECK(worst_joint < 0.002);
  CHECK(worst_follow < 0.05);
  CHECK(lowest > 0.19);
  CHECK(highest < 0.23);
  CHECK(least_up > 0.9);  // the Crazyflie never tipped
  // carried along the Burger's circle (0.1 m/s for 30 s: 3 m of arc)
  CHECK((rod.root().pose().position - start).norm() > 1.5);
  CHECK(recorder.summary().crashed == 0);
}

TEST_CASE("ground scenarios: carry: without the Crazyflie's hold, the rod's end falls", "[scenario][carry]") {
  // (the Crazyflie would take hold at 100 s)
  Scene scene = groundExample("carry.xml", {{"artifact[name=cf]/driver@hold_time", "100", {}}});
  Environment& env = *scene.environment;
  const Artifact& rod = *std::as_const(env).findArtifact("rod");
  env.step(1000);  // 2 s
  CHECK(rod.root().attachments() == 1);
  // hanging from the Burger's plate (0.21 m up), the rod's far end is on the floor
  CHECK(rod.root().pose().transformPoint(Vec3(-0.19, 0, 0)).z() < 0.02);
}

TEST_CASE("ground scenarios: carry: the same bits on 1 and 2 threads and after a restore while both hold the rod",
          "[scenario][carry]") {
  auto run = [](int threads) {
    SceneOptions options = testOptions();
    options.threads = threads;
    Scene scene = loadScene(kGround / "carry.xml", options);
    Environment& env = *scene.environment;
    env.step(1500);  // 3 s: held since the first step
    const auto state = env.saveState();
    env.step(1500);
    Scene again = loadScene(kGround / "carry.xml", options);
    again.environment->restoreState(state);
    again.environment->step(1500);
    CHECK(again.environment->stateHash() == env.stateHash());
    return env.stateHash();
  };
  CHECK(run(1) == run(2));
}
