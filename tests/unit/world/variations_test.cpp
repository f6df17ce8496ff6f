// Constants varied between steps (variations.cpp, Environment::vary, ssx/variation.hpp): a
// varied thrust coefficient changes the flight, travels with a saved state into an environment
// that never varied it, and restoring a state without it gives the scene's bits again; mass and
// inertia scale the bodies on ODE and Bullet and survive an engine switch; the IMU's noise and
// the wind vary; unknown names and values out of range are refused before anything changes.
#include "scene_util.hpp"
#include "test_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace ssx;
using Catch::Contains;
using ssx::test::kArtifacts;

namespace {

// one Crazyflie taking off to 1 m above its start, on `engine`
Scene crazyflie(const std::string& engine = "ode") {
  return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"3\" threads=\"1\"/><physics engine=\"" +
                                 engine + "\"/><type name=\"cf\" file=\"" + (kArtifacts / "crazyflie.xml").string() +
                                 "\"/><ground/><swarm type=\"cf\" count=\"1\" name=\"cf{i}\" xyz=\"0 0 0.05\">"
                                 "<driver offset=\"0 0 1\"/></swarm></scene>",
                             "cf.xml", kArtifacts);
}

const Artifact& robot(const Environment& env) { return *env.findArtifact("cf0"); }

// one vehicle of artifact file `type` named `name`, 1 m up, its driver given `driver` attributes
Scene hovering(const std::string& type, const std::string& name, const std::string& driver) {
  return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"3\" threads=\"1\"/><type name=\"t\" "
                             "file=\"" + (kArtifacts / type).string() + "\"/><ground/><artifact type=\"t\" name=\"" +
                                 name + "\" xyz=\"0 0 1\"><driver " + driver + "/></artifact></scene>",
                             "one.xml", kArtifacts);
}

double gyroSpread(Environment& env, int steps) {
  // the spread of the gyroscope's x reading from one step to the next (motion is far slower)
  const Sensor* imu = nullptr;
  for (std::size_t k = 0; k < robot(env).sensorCount() && imu == nullptr; ++k)
    if (dynamic_cast<const ImuMeasurement*>(&robot(env).sensor(k).latest()) != nullptr) imu = &robot(env).sensor(k);
  REQUIRE(imu != nullptr);
  double sum = 0, last = 0;
  for (int i = 0; i < steps; ++i) {
    env.step(1);
    const double x = static_cast<const ImuMeasurement&>(imu->latest()).gyroscope.x();
    if (i > 0) sum += (x - last) * (x - last);
    last = x;
  }
  return std::sqrt(sum / (steps - 1));
}

}  // namespace

TEST_CASE("variations: a varied constant changes the flight, travels with a saved state, and neutral is the scene",
          "[variations]") {
  Scene a = crazyflie();
  Environment& env = *a.environment;
  env.step(1000);  // 2 s: up and holding
  const std::vector<std::byte> hovering = env.saveState();
  env.step(200);
  const std::uint64_t nominal = env.stateHash();
  const double nominal_z = robot(env).pose().position.z();

  env.restoreState(hovering);
  env.vary(robot(env), "thrust_coefficient", 0.8);
  CHECK(env.variation(robot(env), "thrust_coefficient") == 0.8);
  const std::vector<std::byte> weak = env.saveState();
  env.step(200);
  const std::uint64_t varied = env.stateHash();
  CHECK(varied != nominal);
  CHECK(robot(env).pose().position.z() < nominal_z - 0.005);  // 20 % less thrust: it sags before the loop catches up

  // restoring a state saved before the variation: the scene's constants again, bit for bit
  env.restoreState(hovering);
  CHECK(env.variation(robot(env), "thrust_coefficient") == 1.0);
  env.step(200);
  CHECK(env.stateHash() == nominal);
  // setting the neutral value by hand is the same
  env.restoreState(weak);
  env.vary(robot(env), "thrust_coefficient", 1.0);
  CHECK(env.saveState() == hovering);
  // a state carries its variations into an environment that never varied anything
  Scene fresh = crazyflie();
  fresh.environment->restoreState(weak);
  CHECK(fresh.environment->variation(robot(*fresh.environment), "thrust_coefficient") == 0.8);
  fresh.environment->step(200);
  CHECK(fresh.environment->stateHash() == varied);
}

TEST_CASE("variations: mass and inertia scale the bodies on ODE and Bullet and survive an engine switch",
          "[variations]") {
  for (const std::string engine : {"ode", "bullet"}) {
    CAPTURE(engine);
    Scene plain = crazyflie(engine), heavy = crazyflie(engine), spinning = crazyflie(engine);
    for (Scene* s : {&plain, &heavy, &spinning}) s->environment->step(1000);
    heavy.environment->vary(robot(*heavy.environment), "mass", 1.5);
    spinning.environment->vary(robot(*spinning.environment), "inertia", 3.0);
    for (Scene* s : {&plain, &heavy, &spinning}) s->environment->step(100);
    // half as heavy again on the same thrust: it sinks until the controller's integrator answers
    CHECK(robot(*heavy.environment).pose().position.z() < robot(*plain.environment).pose().position.z() - 0.01);
    CHECK(spinning.environment->stateHash() != plain.environment->stateHash());
  }
  // varied on ODE, then switched: Bullet's bodies get the varied mass too
  Scene plain = crazyflie(), heavy = crazyflie();
  for (Scene* s : {&plain, &heavy}) s->environment->step(1000);
  heavy.environment->vary(robot(*heavy.environment), "mass", 1.5);
  for (Scene* s : {&plain, &heavy}) s->environment->switchPhysics("bullet");
  for (Scene* s : {&plain, &heavy}) s->environment->step(100);
  CHECK(robot(*heavy.environment).pose().position.z() < robot(*plain.environment).pose().position.z() - 0.01);
  CHECK(heavy.environment->variation(robot(*heavy.environment), "mass") == 1.5);
}

TEST_CASE("variations: the IMU's noise and the wind vary", "[variations]") {
  Scene quiet = crazyflie(), noisy = crazyflie();
  quiet.environment->step(1000);
  noisy.environment->step(1000);
  noisy.environment->vary(robot(*noisy.environment), "gyro_noise", 10.0);
  const double q = gyroSpread(*quiet.environment, 200), n = gyroSpread(*noisy.environment, 200);
  CHECK(n > 5 * q);

  Scene calm = crazyflie(), windy = crazyflie();
  calm.environment->step(1000);
  windy.environment->step(1000);
  windy.environment->vary(robot(*windy.environment), "wind_x", 5.0);
  calm.environment->step(250);
  windy.environment->step(250);
  // blown downwind before the position loop brings it back
  CHECK(robot(*windy.environment).pose().position.x() > robot(*calm.environment).pose().position.x() + 0.002);
}

TEST_CASE("variations: the battery's voltage varies for a vehicle that has one", "[variations]") {
  // the Crazyflie on its firmware's controller: the compensation keeps a command's thrust until the
  // battery cannot give the voltage; full thrust from a weaker battery climbs less
  auto firmware = [] { return hovering("crazyflie.xml", "cf0", "controller=\"crazyflie_pid\""); };
  Scene full = firmware(), low = firmware();
  const auto names = [](const Environment& env) {
    std::vector<std::string> out;
    for (const Variable& v : env.variables(robot(env))) out.emplace_back(v.name);
    return out;
  };
  full.environment->step(100);
  low.environment->step(100);
  const std::vector<std::string> listed = names(*full.environment);
  CHECK(std::find(listed.begin(), listed.end(), "battery_volts") != listed.end());
  low.environment->vary(robot(*low.environment), "battery_volts", -1.7);  // 2.5 V: 0.31 N at most
  for (Scene* s : {&full, &low}) {
    auto* commands = dynamic_cast<CommandInterface*>(s->environment->findArtifact("cf0")->driver());
    REQUIRE(commands != nullptr);
    commands->setCommand(Command::attitude(0, 0, 0, 0.47));  // nearly every motor's 0.12 N
    s->environment->step(150);
  }
  const double climbed_full = robot(*full.environment).pose().position.z() - 1;
  const double climbed_low = robot(*low.environment).pose().position.z() - 1;
  CHECK(climbed_full > 0.1);
  CHECK(climbed_low < 0.5 * climbed_full);
  // a state saved on the low battery keeps it: restored where it was never varied, the same bits
  const std::vector<std::byte> saved = low.environment->saveState();
  low.environment->step(50);
  Scene again = firmware();
  again.environment->step(1);
  again.environment->restoreState(saved);
  again.environment->step(50);
  CHECK(again.environment->stateHash() == low.environment->stateHash());
  CHECK(again.environment->variation(robot(*again.environment), "battery_volts") == -1.7);

  // a battery model, not compensated (thrust follows the voltage): a lower open circuit sinks the hover
  auto mk = [] { return hovering("mk_quad.xml", "mk0", "battery=\"true\""); };
  Scene charged = mk(), drained = mk();
  charged.environment->step(500);
  drained.environment->step(500);
  drained.environment->vary(*drained.environment->findArtifact("mk0"), "battery_volts", -2.0);
  charged.environment->step(150);
  drained.environment->step(150);
  CHECK(drained.environment->findArtifact("mk0")->pose().position.z() <
        charged.environment->findArtifact("mk0")->pose().position.z() - 0.01);
}

TEST_CASE("variations: unknown names and values out of range are refused before anything changes", "[variations]") {
  Scene s = crazyflie();
  Environment& env = *s.environment;
  CHECK_THROWS_WITH(env.vary(robot(env), "mass", 2.0), Contains("not running"));
  env.step(10);
  std::vector<std::string> names;
  for (const Variable& v : env.variables(robot(env))) names.emplace_back(v.name);
  CHECK(names == std::vector<std::string>{"mass", "inertia", "thrust_coefficient", "moment_constant",
                                          "time_constant_up", "time_constant_down", "wind_x", "wind_y", "wind_z",
                                          "battery_volts", "gyro_noise", "accel_noise"});
  const std::vector<std::byte> before = env.saveState();
  CHECK_THROWS_WITH(env.vary(robot(env), "thrust", 0.9),
                    Contains("no constant 'thrust'") && Contains("thrust_coefficient") && Contains("gyro_noise"));
  CHECK_THROWS_WITH(env.vary(robot(env), "thrust_coefficient", 0.0), Contains("within [0.2, 5]"));
  CHECK_THROWS_WITH(env.vary(robot(env), "mass", std::nan("")), Contains("mass of artifact 'cf0' must be within"));
  CHECK_THROWS_AS(env.variation(robot(env), "nothing"), ConfigError);
  CHECK(env.saveState() == before);
  // the ground has no body and no plugin: nothing varies
  CHECK(env.variables(*env.findArtifact("ground")).empty());
  CHECK_THROWS_WITH(env.vary(*env.findArtifact("ground"), "mass", 2.0), Contains("(it has: none)"));
}
