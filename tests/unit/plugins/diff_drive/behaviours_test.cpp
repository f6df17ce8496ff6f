// The diff_drive's behaviours behind the controller interface: a built-in one, one of a user's own
// (a driver derived from DiffDrive), the sensors each needs.
#include "diff_drive.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

using namespace ssx;
using namespace ssx::ground;

namespace {

const std::filesystem::path kArtifacts = std::filesystem::path(SSX_EXAMPLES_DIR) / "artifacts";

// a behaviour of one's own: spins on the spot, counting its runs
class Spin final : public GroundController {
 public:
  void step(double, GroundInputs& in) override {
    ++runs;
    in.drive.setWheels(-2, 2);
  }
  void saveState(StateWriter& out) const override { out.write(runs); }
  void loadState(StateReader& in) override { in.read(runs); }
  std::int64_t runs = 0;
};

class Spinner final : public DiffDrive {
 protected:
  std::unique_ptr<GroundController> makeController(const Descriptor&, const Artifact&, const DriveModel&) override {
    return std::make_unique<Spin>();
  }
};

// a 1 kg box on the ground driven by `driver` as a swarm-model robot: 2 cm wheels on a 10 cm axle
Scene boxDrivenBy(std::unique_ptr<Driver> driver, const std::string& controller, const std::string& twist = "0 0 0") {
  Scene s = loadSceneFromString(
      "<scene><environment timestep=\"0.002\"/><ground/><type name=\"box\" file=\"box.xml\"/>"
      "<artifact name=\"b\" type=\"box\" xyz=\"0 0 0.1\"/></scene>",
      "behaviours.xml", kArtifacts);
  Descriptor params("driver");
  params.setDeclarations(DiffDrive::kParameters);
  params.set("wheel_radius", 0.02).set("axle_length", 0.1).set("max_wheel_speed", 10.0);
  if (controller != "none") params.set("controller", controller).set("twist", twist);
  s.environment->findArtifact("b")->setDriver(std::move(driver), params);
  return s;
}

}  // namespace

TEST_CASE("the twist behaviour drives a circle of radius v / w until a command takes over", "[diff_drive]") {
  Scene s = boxDrivenBy(std::make_unique<DiffDrive>(), "twist", "0.1 0.5 0");
  Environment& env = *s.environment;
  env.step(3000);  // 6 s
  const BodyState state = env.findArtifact("b")->state();
  CHECK(state.angular_velocity.z() == Approx(0.5).margin(1e-3));
  CHECK(state.linear_velocity.head<2>().norm() == Approx(0.1).margin(1e-3));
  // the circle's centre is 0.2 m to the left of the start (heading +x)
  CHECK(std::hypot(state.pose.position.x(), state.pose.position.y() - 0.2) == Approx(0.2).margin(2e-3));
  auto* command = dynamic_cast<CommandInterface*>(env.findArtifact("b")->driver());
  REQUIRE(command != nullptr);
  command->setCommand(Command::wheels(3, 3));
  env.step(500);
  CHECK(std::abs(env.findArtifact("b")->state().angular_velocity.z()) < 1e-3);
}

TEST_CASE("a behaviour of one's own: a driver derived from DiffDrive makes it, it runs every step and is saved",
          "[diff_drive]") {
  auto driver = std::make_unique<Spinner>();
  Spinner& spinner = *driver;
  Scene s = boxDrivenBy(std::move(driver), "none");
  Environment& env = *s.environment;
  env.step(500);
  const auto* spin = dynamic_cast<const Spin*>(spinner.controller());
  REQUIRE(spin != nullptr);
  CHECK(spin->runs == 500);
  // wheels -2 and 2 rad/s: turns on the spot at 2 r w / axle = 0.8 rad/s
  CHECK(env.findArtifact("b")->state().angular_velocity.z() == Approx(0.8).margin(1e-3));
  CHECK(env.findArtifact("b")->state().linear_velocity.head<2>().norm() < 1e-3);
  const std::vector<std::byte> saved = env.saveState();
  env.step(10);
  env.restoreState(saved);
  CHECK(spin->runs == 500);
}

TEST_CASE("a behaviour is refused on a robot without the sensors it reads", "[diff_drive]") {
  Scene s =
      loadSceneFromString("<scene><type name=\"box\" file=\"box.xml\"/><artifact name=\"b\" type=\"box\"/></scene>",
                          "behaviours.xml", kArtifacts);
  const Artifact& box = *s.environment->findArtifact("b");
  for (const char* controller : {"diffusion", "beeclust", "foraging"}) {
    Descriptor params("driver");
    params.setDeclarations(DiffDrive::kParameters);
    params.set("controller", controller);
    CHECK_THROWS_WITH(validateBehaviour(params, box), Catch::Contains("needs a proximity sensor"));
  }
  Descriptor twist("driver");
  twist.setDeclarations(DiffDrive::kParameters);
  twist.set("controller", "twist");
  CHECK_NOTHROW(validateBehaviour(twist, box));
}
