// The clock sensor: the simulated time of the step it ran in, at its period, kept across a save and
// restore.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

using namespace ssx;
namespace fs = std::filesystem;

namespace {

// a box with a clock every 3 steps of 4 ms
Scene clockScene() {
  const fs::path dir = fs::current_path() / "clock_test";
  fs::create_directories(dir);
  std::ofstream(dir / "timed_box.xml") << R"(<artifact>
  <physic name="body" mass="1"><box size="0.1 0.1 0.1"/></physic>
  <sensor plugin="clock" period="3"/>
</artifact>
)";
  return loadSceneFromString(R"(<scene><environment timestep="0.004"/><type name="box" file="timed_box.xml"/>
    <artifact name="b" type="box" xyz="0 0 1"/></scene>)",
                             "clock.xml", dir);
}

const ClockMeasurement& clock(Environment& env) {
  const Artifact& a = *env.findArtifact("b");
  return dynamic_cast<const ClockMeasurement&>(a.sensor(0).latest());
}

}  // namespace

TEST_CASE("clock: reports the step it ran in and its time, every period steps", "[clock]") {
  Scene scene = clockScene();
  Environment& env = *scene.environment;
  for (int k = 1; k <= 10; ++k) {
    env.step();
    const ClockMeasurement& c = clock(env);
    const std::int64_t ran = (k - 1) / 3 * 3;  // steps 0, 3, 6, 9
    INFO("after step " << k);
    CHECK(c.step == ran);
    CHECK(c.stamp == (ran + 1) * 4'000'000);  // sensors measure the state at the end of their step
    CHECK(c.seconds == toSeconds(c.stamp));
  }
}

TEST_CASE("clock: its last reading is part of a saved state", "[clock][state]") {
  Scene first = clockScene();
  first.environment->step(8);  // last ran in step 6
  const auto saved = first.environment->saveState();
  Scene second = clockScene();
  second.environment->start();
  second.environment->restoreState(saved);
  CHECK(clock(*second.environment).step == 6);
  CHECK(clock(*second.environment).seconds == clock(*first.environment).seconds);
}
