// Fidelity effects together: every one on at once stays reproducible.
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

TEST_CASE("every effect on at once: bitwise the same on 1, 2 and 4 threads, and after a save and restore",
          "[fidelity]") {
  // 16 Crazyflies in two layers 1 m apart (downwash between them), wind, a gust, turbulence (with a
  // rotor drag: gym-pybullet-drones' cf2x figure in rad/s), battery, estimator, latencies, the
  // serial link, ground effect and a mass mismatch
  auto load = [](int threads) {
    const std::string driver = R"(<driver offset="0 0 0.3" downwash="true" wind="1 0.5 0" gust="0 1 0" gust_start="0.2"
        gust_duration="0.4" turbulence_w20="7.7" rotor_drag_coefficient="8.76e-6" battery="true"
        battery_full_voltage="4.2" battery_empty_voltage="3.5" battery_nominal_voltage="3.9"
        battery_zero_thrust_voltage="1.9" thrust_estimator="true" command_delay="0.004" command_link="true"
        ground_effect="true" controller_mass="0.026"/>)";
    const std::string sensor = R"(<sensor index="1" delay="0.004" delay_jitter="0.004"/>)";
    const std::string xml = R"(<scene><environment timestep="0.002" seed="9" threads=")" + std::to_string(threads) +
                            R"("/><type name="cf" file="crazyflie.xml"/><ground/>
      <swarm type="cf" count="8" name="low{i}" spacing="0.3" columns="4" xyz="0 0 0.5">)" + sensor + driver +
                            R"(</swarm>
      <swarm type="cf" count="8" name="high{i}" spacing="0.3" columns="4" xyz="0.01 0 1.5">)" + sensor + driver +
                            R"(</swarm></scene>)";
    return loadSceneFromString(xml, "everything.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
  };
  Scene one = load(1), two = load(2), four = load(4);
  one.environment->step(300);
  const auto saved = one.environment->saveState();
  one.environment->step(300);
  two.environment->step(600);
  four.environment->step(600);
  CHECK(one.environment->stateHash() == two.environment->stateHash());
  CHECK(one.environment->stateHash() == four.environment->stateHash());
  Scene again = load(2);
  again.environment->restoreState(saved);
  again.environment->step(300);
  CHECK(again.environment->stateHash() == one.environment->stateHash());
  // and they flew: every one is above the ground and near its hover point
  for (std::size_t i = 0; i < 8; ++i)
    for (const char* layer : {"low", "high"}) {
      const Artifact& cf = *one.environment->findArtifact(layer + std::to_string(i));
      CHECK(cf.pose().position.z() > 0.5);
    }
}
