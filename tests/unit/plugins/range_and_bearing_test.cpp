// range_and_bearing: robots within range receive each other's payload with range, bearing and
// elevation in their own frame; beyond range nothing; occlusion by a wall; a loss probability;
// the same messages on 1 and 2 threads.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace ssx;
using namespace ssx::test;
using Catch::Contains;

namespace {

Scene scene(const std::string& board, int threads = 1, const std::string& extra = "") {
  const std::string xml = R"(<scene><environment timestep="0.01" threads=")" + std::to_string(threads) + R"("/>
    <type name="epuck" file=")" + (kArtifacts / "epuck.xml").string() + R"("/>
    <ground/>)" + extra + R"(
    <artifact name="a" type="epuck" xyz="0 0 0" rpy="0 0 0.5">)" + board + R"(</artifact>
    <artifact name="b" type="epuck" xyz="0.3 0.3 0">)" + board + R"(</artifact>
    <artifact name="far" type="epuck" xyz="2 0 0">)" + board + R"(</artifact></scene>)";
  return loadSceneFromString(xml, "rab.xml", kArtifacts, testOptions());
}

const Sensor& board(Environment& env, const std::string& name) {
  const Artifact& a = *env.findArtifact(name);
  for (std::size_t i = 0; i < a.sensorCount(); ++i)
    if (dynamic_cast<const RangeBearingMeasurement*>(&a.sensor(i).latest()) != nullptr) return a.sensor(i);
  throw std::runtime_error("no board");
}

const RangeBearingMeasurement& received(Environment& env, const std::string& name) {
  return dynamic_cast<const RangeBearingMeasurement&>(board(env, name).latest());
}

RangeBearingInterface& sender(Environment& env, const std::string& name) {
  return const_cast<RangeBearingInterface&>(dynamic_cast<const RangeBearingInterface&>(board(env, name)));
}

}  // namespace

TEST_CASE("range_and_bearing: a robot in range receives the other's payload, range and bearing in its own frame",
          "[range_and_bearing]") {
  Scene s = scene("");
  Environment& env = *s.environment;
  env.step();
  const std::uint8_t data[] = {1, 2, 3, 4};
  sender(env, "b").setData(data);
  CHECK_THROWS_WITH(sender(env, "b").setData(std::span(data, 3)), Contains("a payload of 4 bytes, got 3"));
  env.step();
  const RangeBearingMeasurement& a = received(env, "a");
  REQUIRE(a.messages.size() == 1);  // b; "far" is 2 m away, beyond 0.8 m
  const auto& m = a.messages[0];
  CHECK(m.sender == env.findArtifact("b")->index());
  CHECK(m.range == Approx(std::hypot(0.3, 0.3)).margin(1e-3));
  CHECK(m.bearing == Approx(M_PI / 4 - 0.5).margin(1e-3));  // a faces 0.5 rad
  CHECK(m.elevation == Approx(0).margin(1e-3));
  CHECK(m.data == std::vector<std::uint8_t>{1, 2, 3, 4});
  // b hears a's zeros, at the opposite bearing in its own frame (facing 0)
  REQUIRE(received(env, "b").messages.size() == 1);
  CHECK(received(env, "b").messages[0].bearing == Approx(-3 * M_PI / 4).margin(1e-3));
  CHECK(received(env, "b").messages[0].data == std::vector<std::uint8_t>(4, 0));
  CHECK(received(env, "far").messages.empty());
}

TEST_CASE("range_and_bearing: a wall between two robots stops their messages when occlusion is on", "[range_and_bearing]") {
  const std::string wall = R"(<obstacle name="wall" xyz="0.15 0.15 0.05" rpy="0 0 -0.785398"><box size="0.01 0.3 0.1"/></obstacle>)";
  for (const bool occlusion : {false, true}) {
    INFO("occlusion " << occlusion);
    Scene s = scene(std::string(R"(<sensor index="1" height="0.05" occlusion=")") +
                        (occlusion ? "true" : "false") + R"("/>)",
                    1, wall);
    Environment& env = *s.environment;
    env.step(2);
    CHECK(received(env, "a").messages.size() == (occlusion ? 0u : 1u));
  }
}

TEST_CASE("range_and_bearing: messages are lost at their probability, the same on 1 and 2 threads", "[range_and_bearing]") {
  auto run = [](int threads) {
    Scene s = scene(R"(<sensor index="1" loss="0.3" range_noise="0.01" bearing_noise="0.05"/>)", threads);
    Environment& env = *s.environment;
    std::vector<double> ranges;
    int got = 0;
    for (int i = 0; i < 2000; ++i) {
      env.step();
      for (const auto& m : received(env, "a").messages) {
        ++got;
        ranges.push_back(m.range);
      }
    }
    return std::make_pair(got, ranges);
  };
  const auto [got, ranges] = run(1);
  CHECK(got == Approx(0.7 * 2000).margin(3 * std::sqrt(2000 * 0.3 * 0.7)));
  double mean = 0;
  for (double r : ranges) mean += r / static_cast<double>(ranges.size());
  CHECK(mean == Approx(std::hypot(0.3, 0.3)).margin(0.002));
  CHECK(run(2).second == ranges);
}

TEST_CASE("range_and_bearing: a board without a driver sends its `data` for good (a beacon), bad bytes are refused",
          "[range_and_bearing]") {
  Scene s = scene(R"(<sensor index="1" data="1 200"/>)");
  Environment& env = *s.environment;
  env.step(2);
  const RangeBearingMeasurement& m = received(env, "a");
  REQUIRE(m.messages.size() == 1);  // from b
  CHECK(m.messages[0].data == std::vector<std::uint8_t>{1, 200, 0, 0});
  CHECK_THROWS_WITH(scene(R"(<sensor index="1" data="1 256"/>)"), Contains("'256' is not a byte"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="1" data="1 2 3 4 5"/>)"), Contains("more bytes than the payload holds (4)"));
}
