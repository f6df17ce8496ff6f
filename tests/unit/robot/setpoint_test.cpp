// Set-points: a driver in a plugin library found through ssx::SetpointInterface follows the
// set-point it is given, holds it, and says which one it tracks.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

using namespace ssx;

TEST_CASE("set-points: a quadrotor found through SetpointInterface flies to the set-point and holds it",
          "[setpoint][quadrotor]") {
  Scene scene = loadSceneFromString(R"(<scene><environment timestep="0.002"/>
    <type name="q" file="mk_quad.xml"/><ground/><artifact name="q" type="q" xyz="0 0 1"/></scene>)",
                                    "setpoint.xml", test::kArtifacts);
  Environment& env = *scene.environment;
  env.step(500);  // 1 s hovering at its start
  auto* tracker = dynamic_cast<SetpointInterface*>(env.findArtifact("q")->driver());
  REQUIRE(tracker != nullptr);
  Setpoint sp;
  sp.position = Vec3(1, -0.5, 1.5);
  sp.yaw = 0.3;
  tracker->setSetpoint(sp);
  CHECK(tracker->currentSetpoint().position == sp.position);
  CHECK(tracker->currentSetpoint().yaw == sp.yaw);
  env.step(5000);  // 10 s
  CHECK((env.findArtifact("q")->pose().position - sp.position).norm() < 0.05);
  CHECK(tracker->currentSetpoint().position == sp.position);  // held, not replaced by the scene's reference
}
