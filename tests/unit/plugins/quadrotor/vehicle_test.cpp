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
  const RotorParams rp = *preset("mk_quad");
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
