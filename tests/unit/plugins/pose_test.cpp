// The pose sensor: latency and jitter against their definitions, and across a save and restore.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

using namespace ssx;
namespace fs = std::filesystem;

namespace {

// a quadrotor-sized body (examples/artifacts/hover_body.xml: pose sensor every 2 steps of 2 ms)
Scene poseScene(const std::string& sensor_attributes) {
  const std::string xml = R"(<scene><environment timestep="0.002" seed="4"/>
    <type name="body" file="hover_body.xml"/>
    <artifact name="b" type="body" xyz="0 0 2"><sensor index="0" position_noise="0" velocity_noise="0" )" +
                          sensor_attributes + R"(/></artifact></scene>)";
  return loadSceneFromString(xml, "latency.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
}

struct Trace {
  std::map<Nanoseconds, double> truth;               // x after each step
  std::vector<std::pair<Nanoseconds, Nanoseconds>> delivered;  // (time delivered, stamp)
  std::vector<double> measured_x;
  bool exact = true;                                 // every measurement is the true state at its stamp
};

// moves the body along x = 0.2 sin(2 pi t) (set before each step) and records what the sensor says
Trace follow(Scene& scene, int steps) {
  Environment& env = *scene.environment;
  env.start();
  Artifact& b = *env.findArtifact("b");
  const int body = b.root().bodyIndex();
  Trace t;
  Nanoseconds last_stamp = -1;
  for (int k = 0; k < steps; ++k) {
    const double time = toSeconds(env.time());
    BodyState s = env.bodyState(body);
    s.pose.position = Vec3(0.2 * std::sin(2 * std::numbers::pi * time), 0, 2);
    s.linear_velocity = Vec3(0.2 * 2 * std::numbers::pi * std::cos(2 * std::numbers::pi * time), 0, 0);
    s.angular_velocity.setZero();
    env.setBodyState(body, s);
    env.step();
    t.truth[env.time()] = b.pose().position.x();
    const auto& m = dynamic_cast<const PoseMeasurement&>(b.sensor(0).latest());
    if (k % 2 != 0) continue;  // the sensor runs in every second step, from the first
    t.delivered.emplace_back(env.time(), m.stamp);
    t.measured_x.push_back(m.pose.position.x());
    const auto it = t.truth.find(m.stamp);
    t.exact = t.exact && it != t.truth.end() && it->second == m.pose.position.x() && m.stamp >= last_stamp;
    last_stamp = m.stamp;
  }
  return t;
}

}  // namespace

TEST_CASE("pose sensor latency: a sine comes back delayed by `delay`, within one sample", "[fidelity]") {
  Scene scene = poseScene(R"(delay="0.012")");
  const Trace t = follow(scene, 2000);
  CHECK(t.exact);
  // after the first 12 ms every measurement was captured exactly 12 ms before it is delivered
  for (std::size_t i = 3; i < t.delivered.size(); ++i) REQUIRE(t.delivered[i].first - t.delivered[i].second == 12'000'000);
  // the lag that best aligns the measured sine with the true one, in sensor samples (4 ms)
  std::vector<double> truth_x;
  for (const auto& [time, stamp] : t.delivered) truth_x.push_back(t.truth.at(time));
  int best = -1;
  double best_error = 1e9;
  for (int lag = 0; lag < 10; ++lag) {
    double e = 0;
    for (std::size_t i = 20; i < truth_x.size(); ++i) e += std::abs(t.measured_x[i] - truth_x[i - static_cast<std::size_t>(lag)]);
    if (e < best_error) best_error = e, best = lag;
  }
  CHECK(std::abs(best * 4.0 - 12.0) <= 4.0);
}

TEST_CASE("pose sensor latency with jitter: lags between delay and delay + jitter, never going back", "[fidelity]") {
  Scene scene = poseScene(R"(delay="0.004" delay_jitter="0.008")");
  const Trace t = follow(scene, 4000);
  CHECK(t.exact);  // the true state at its stamp, stamps never decreasing
  std::set<Nanoseconds> lags;
  for (std::size_t i = 5; i < t.delivered.size(); ++i) lags.insert(t.delivered[i].first - t.delivered[i].second);
  CHECK(lags == std::set<Nanoseconds>{4'000'000, 8'000'000, 12'000'000});
}

TEST_CASE("pose sensor latency must be whole sensor periods, and survives a save and restore", "[fidelity]") {
  try {
    (void)poseScene(R"(delay="0.005")");
    FAIL("loaded");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Catch::Contains("latency.xml:3: error: <sensor>: sensor 0 'pose': parameter 'delay' = 0.005 s "
                                         "must be a whole number of the sensor's periods (4.000000 ms)"));
  }
  Scene a = poseScene(R"(delay="0.004" delay_jitter="0.008")");
  Scene b = poseScene(R"(delay="0.004" delay_jitter="0.008")");
  a.environment->step(301);
  const auto saved = a.environment->saveState();
  a.environment->step(200);
  const auto& ma = dynamic_cast<const PoseMeasurement&>(a.environment->findArtifact("b")->sensor(0).latest());
  b.environment->restoreState(saved);
  b.environment->step(200);
  const auto& mb = dynamic_cast<const PoseMeasurement&>(b.environment->findArtifact("b")->sensor(0).latest());
  CHECK(ma.stamp == mb.stamp);
  CHECK(ma.pose.position == mb.pose.position);
  CHECK(a.environment->stateHash() == b.environment->stateHash());
}
