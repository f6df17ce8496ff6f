// examples/custom_controller: a driver of one's own (pd_quadrotor) on ssx's vehicle, wind and
// references, with a controller that is not the TeleKyb cascade.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <filesystem>
#include <stdexcept>

using namespace ssx;
namespace fs = std::filesystem;

namespace {

const fs::path kExample = fs::path(SSX_EXAMPLES_DIR) / "custom_controller";

Scene pdScene(const std::string& body) {
  SceneOptions options;
  options.plugin_path = {SSX_PD_PLUGIN_DIR};
  return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"2\"/><ground/>"
                             "<type name=\"pd\" file=\"pd_quad.xml\"/>" +
                                 body + "</scene>",
                             "pd.xml", kExample, options);
}

}  // namespace

TEST_CASE("a controller of one's own flies ssx's vehicle to its hover point and to set-points", "[quadrotor][custom]") {
  Scene s = pdScene("<artifact name=\"q\" type=\"pd\" xyz=\"0 0 0.05\"><driver offset=\"0 0 1\"/></artifact>");
  Environment& env = *s.environment;
  Artifact& q = *env.findArtifact("q");
  env.step(2500);  // 5 s
  CHECK((q.pose().position - Vec3(0, 0, 1.05)).norm() < 0.03);
  auto& input = dynamic_cast<CommandInterface&>(*q.driver());
  Setpoint sp;
  sp.position = Vec3(1, -1, 2);
  sp.yaw = 0.7;
  input.setSetpoint(sp);
  env.step(3000);
  CHECK((q.pose().position - sp.position).norm() < 0.03);
  const Vec3 forward = q.pose().orientation * Vec3::UnitX();
  CHECK(std::atan2(forward.y(), forward.x()) == Approx(0.7).margin(0.02));
  // it takes the levels it implements and refuses the others, unchanged
  input.setCommand(Command::velocityYawRate(Vec3(0.5, 0, 0)));
  env.step(1500);
  CHECK(q.state().linear_velocity.x() == Approx(0.5).margin(0.05));
  CHECK_THROWS_WITH(input.setCommand(Command::attitude(0, 0, 0, 8)),
                    Catch::Contains("takes no commands at the attitude level"));
  CHECK(input.commandLevel() == CommandLevel::Velocity);
}

TEST_CASE("the example scene of the custom controller runs: hover, eight and trajectory in the wind",
          "[quadrotor][custom]") {
  SceneOptions options;
  options.plugin_path = {SSX_PD_PLUGIN_DIR};
  Scene s = loadScene(kExample / "pd_scene.xml", options);
  Environment& env = *s.environment;
  env.step(5000);  // 10 s
  // the trajectory's last row (from 8 s on) and the hover point, in 1 m/s of wind with turbulence
  CHECK((env.findArtifact("path")->pose().position - Vec3(-3, 0, 1.5)).norm() < 0.15);
  CHECK((env.findArtifact("hover")->pose().position - Vec3(0, 0, 1.05)).norm() < 0.15);
  CHECK(env.findArtifact("eight")->pose().position.z() > 1.0);
}
