// The vehicle part alone: rotors and motors on a body, without effects or controller.
#include "vehicle.hpp"
#include "part_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace ssx;
using namespace ssx::quadrotor;
using namespace ssx::quadrotor::test;
namespace fs = std::filesystem;

TEST_CASE("a vehicle alone: its rotors at the hover speed carry a body of its weight", "[quadrotor][parts]") {
  // a 1 kg box with no driver; the test spins the vehicle's rotors and applies its wrench each step
  Scene s = sceneOf("<artifact name=\"b\" type=\"box\" xyz=\"0 0 2\"/>");
  Environment& env = *s.environment;
  env.start();
  Artifact& box = *env.findArtifact("b");
  const RotorParams rp = RotorParams{};
  const double g = -env.settings().physics.gravity.z();
  for (double factor : {1.0, 1.05}) {
    Vehicle vehicle;
    vehicle.configure(RotorModel(plus(), rp), Vec3::Zero(), std::nullopt);
    const double hover = std::sqrt(1.0 * g / (4 * rp.thrust_coefficient));
    const std::vector<double> speeds(4, factor * hover);
    vehicle.spinAt(speeds);
    const double z0 = box.pose().position.z();
    for (int i = 0; i < 500; ++i) {  // 1 s
      vehicle.stepMotors(0.002, speeds);
      const BodyState state = box.root().state();
      vehicle.applyWrench(box.root(), state, env.bodyState(box.root().bodyIndex()), Vec3::Zero());
      env.step();
    }
    const double climbed = box.pose().position.z() - z0;
    // 5 % more speed is 10.25 % more thrust: about 0.5 * 1.0 m/s^2 in 1 s (less the rotor drag)
    INFO("speed factor " << factor << " climbed " << climbed << " m");
    if (factor == 1.0)
      CHECK(std::abs(climbed) < 0.005);
    else
      CHECK(climbed == Approx(0.5 * 0.1025 * g).epsilon(0.1));
    CHECK(box.pose().position.head<2>().norm() < 1e-6);  // a symmetric vehicle in still air stays put
  }
}

TEST_CASE("the installed presets: mk_quad writes out the model's defaults, and each gives a whole vehicle",
          "[quadrotor][parts]") {
  const fs::path dir = fs::path(SSX_EXAMPLES_DIR) / "presets" / "quadrotor";
  auto vehicleOf = [&](const std::string& name) {
    const Descriptor preset = readXmlFile(dir / (name + ".xml"));
    Descriptor params("driver");
    params.setDeclarations(kVehicleParameters);
    for (const Descriptor& p : preset.children())
      if (p.find("name")->value != "controller") params.set(p.find("name")->value, p.find("value")->value);
    params.set("battery", true);
    return VehicleParams(params);
  };
  const VehicleParams mk = vehicleOf("mk_quad");
  CHECK(mk.rotor == RotorParams{});
  const BatteryParams b{};
  REQUIRE(mk.battery);
  CHECK(mk.battery->full_voltage == b.full_voltage);
  CHECK(mk.battery->empty_voltage == b.empty_voltage);
  CHECK(mk.battery->capacity == b.capacity);
  CHECK(mk.battery->resistance == b.resistance);
  CHECK(mk.battery->efficiency == b.efficiency);
  CHECK(mk.battery->nominal_voltage == b.nominal_voltage);
  CHECK(mk.battery->zero_thrust_voltage == b.zero_thrust_voltage);
  CHECK(mk.battery->compensated == b.compensated);
  // the others differ where their sources say (docs/quadrotor-reference.md, section 1)
  const VehicleParams cf = vehicleOf("crazyflie");
  CHECK(cf.rotor.thrust_coefficient == 2.27e-8);
  CHECK(cf.rotor.max_rotor_speed == 2501);
  CHECK(cf.battery->compensated);
  CHECK(cf.battery->capacity == 0.25);
  const VehicleParams hb = vehicleOf("hummingbird");
  CHECK(hb.rotor.thrust_coefficient == 8.54858e-6);
  CHECK(hb.rotor.rotor_radius == 0.1);
  CHECK_FALSE(hb.battery->compensated);
}

TEST_CASE("rotor_thrust_factors: each rotor's thrust times its factor, their count and range checked",
          "[quadrotor][parts]") {
  auto paramsWith = [](const std::string& factors) {
    Descriptor params("driver");
    params.setDeclarations(kVehicleParameters);
    params.set("rotor_thrust_factors", factors);
    return params;
  };
  const VehicleParams vp(paramsWith("0.8 1 1 1.2"));
  REQUIRE(vp.thrust_factors == std::vector<double>{0.8, 1.0, 1.0, 1.2});
  CHECK(VehicleParams(paramsWith("")).thrust_factors.empty());
  CHECK_THROWS_WITH(VehicleParams(paramsWith("0.8 1 1")), Catch::Contains("one factor per rotor (4), got 3"));
  CHECK_THROWS_WITH(VehicleParams(paramsWith("2 1 1 1")), Catch::Contains("'2' is not a factor from 0.5 to 1.5"));
  CHECK_THROWS_WITH(VehicleParams(paramsWith("1 1 x 1")), Catch::Contains("'x' is not a factor"));

  const RotorParams rp = RotorParams{};
  Vehicle vehicle;
  vehicle.configure(RotorModel(plus(), rp), Vec3::Zero(), std::nullopt, vp.thrust_factors);
  const double w = 400, t = rp.thrust_coefficient * w * w;  // one rotor's thrust, as the model gives it
  vehicle.spinAt(std::vector<double>(4, w));
  Vec3 force, torque;
  vehicle.rotors().wrench(Vec3::Zero(), Vec3::Zero(), force, torque);
  CHECK(force.z() == Approx(4.0 * t));  // 0.8 + 1 + 1 + 1.2
  // rotor 0 (+x) gives 0.8 t and rotor 2 (-x) t: a pitching torque; rotor 1 (+y) t, rotor 3 (-y) 1.2 t
  CHECK(torque.y() == Approx(0.225 * 0.2 * t));
  CHECK(torque.x() == Approx(-0.225 * 0.2 * t));
  CHECK(torque.z() == Approx(rp.moment_constant * 0.4 * t));
  // with ground effect or a battery the gains are renewed every step: the factors stay in them
  vehicle.updateGains(0.002, [](std::size_t) { return 1.5; });
  const auto gains = vehicle.rotors().thrustGains();
  CHECK(std::vector<double>(gains.begin(), gains.end()) == std::vector<double>{1.5 * 0.8, 1.5, 1.5, 1.5 * 1.2});
  // without factors, a symmetric vehicle: no torque
  Vehicle plain;
  plain.configure(RotorModel(plus(), rp), Vec3::Zero(), std::nullopt);
  plain.spinAt(std::vector<double>(4, w));
  plain.rotors().wrench(Vec3::Zero(), Vec3::Zero(), force, torque);
  CHECK(force.z() == 4 * t);
  CHECK(torque.norm() == 0);
}
