// The quadrotor driver in flight, loaded as a user's scene loads it.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <vector>

using namespace ssx;

namespace {

const std::filesystem::path kArtifacts = std::filesystem::path(SSX_EXAMPLES_DIR) / "artifacts";
const std::filesystem::path kScenes = std::filesystem::path(SSX_EXAMPLES_DIR) / "scenes";

Scene quadScene(const std::string& overrides, double z, std::uint64_t seed = 1, const std::string& type = "mk_quad") {
  const std::string xml = "<scene><environment timestep=\"0.002\" seed=\"" + std::to_string(seed) +
                          "\"/><type name=\"q\" file=\"" + type +
                          ".xml\"/><ground/>"
                          "<artifact name=\"quad\" type=\"q\" xyz=\"0 0 " +
                          std::to_string(z) + "\">" + overrides + "</artifact></scene>";
  return loadSceneFromString(xml, "quad.xml", kArtifacts);
}

}  // namespace

TEST_CASE("closed-loop noiseless hover drifts less than 1 cm in 10 s", "[quadrotor][flight]") {
  for (const char* type : {"mk_quad", "hummingbird", "crazyflie"}) {
    INFO(type);
    Scene s = quadScene(
        "<sensor index=\"0\" noise=\"false\"/><sensor index=\"1\" position_noise=\"0\" velocity_noise=\"0\"/>", 1.0, 1,
        type);
    Environment& env = *s.environment;
    Artifact& quad = *env.findArtifact("quad");
    env.step(500);  // settle 1 s after release
    const Vec3 start = quad.pose().position;
    double worst = 0;
    for (int i = 0; i < 5000; ++i) {
      env.step();
      worst = std::max(worst, (quad.pose().position - start).norm());
    }
    INFO("largest excursion " << worst << " m");
    CHECK(worst < 0.01);
    CHECK((quad.pose().position - Vec3(0, 0, 1)).norm() < 0.01);
  }
}

TEST_CASE("a quadrotor takes off from the ground to its hover point", "[quadrotor][flight]") {
  Scene s = quadScene("<driver offset=\"0 0 1\"/>", 0.05, 4);
  s.environment->step(2500);  // 5 s
  CHECK((s.environment->findArtifact("quad")->pose().position - Vec3(0, 0, 1.05)).norm() < 0.05);
}

TEST_CASE("an external set-point moves the quadrotor", "[quadrotor][flight]") {
  Scene s = quadScene("<driver reference=\"external\"/>", 1.0, 5);
  Environment& env = *s.environment;
  env.start();
  auto* input = dynamic_cast<SetpointInterface*>(env.findArtifact("quad")->driver());
  REQUIRE(input != nullptr);
  Setpoint sp;
  sp.position = Vec3(1.0, -0.5, 1.5);
  input->setSetpoint(sp);
  env.step(3000);  // 6 s
  CHECK((env.findArtifact("quad")->pose().position - sp.position).norm() < 0.05);
  CHECK(input->currentSetpoint().position == sp.position);
}

TEST_CASE("figure-eight tracking with noise on is stable and its error bounded", "[quadrotor][flight]") {
  for (const char* kind : {"eight_horizontal", "eight_vertical"}) {
    INFO(kind);
    Scene s = loadScene(kScenes / (std::string(kind) + ".xml"));
    Environment& env = *s.environment;
    Artifact& quad = *env.findArtifact("quad");
    env.start();
    auto* tracker = dynamic_cast<SetpointInterface*>(quad.driver());
    REQUIRE(tracker != nullptr);
    double sum = 0, worst = 0;
    int n = 0;
    for (int k = 0; k < 12000; ++k) {  // two periods
      env.step();
      if (k % 10 != 0 || env.time() < toNanoseconds(12.0)) continue;
      const double e = (tracker->currentSetpoint().position - quad.pose().position).norm();
      sum += e;
      worst = std::max(worst, e);
      ++n;
    }
    INFO("mean " << sum / n << " m, worst " << worst << " m");
    CHECK(sum / n < 0.15);
    CHECK(worst < 0.3);
  }
}

TEST_CASE("quadrotors with noisy IMUs fly bitwise identically on 1 and 2 threads", "[quadrotor][determinism]") {
  auto hashAfter = [](int threads) {
    SceneOptions o;
    o.threads = threads;
    Scene s = loadScene(kScenes / "quad_hover.xml", o);
    s.environment->step(1500);
    return s.environment->stateHash();
  };
  CHECK(hashAfter(1) == hashAfter(2));
}
