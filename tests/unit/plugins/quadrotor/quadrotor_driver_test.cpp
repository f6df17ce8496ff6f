// The quadrotor driver in flight, loaded as a user's scene loads it.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
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

TEST_CASE("the crazyflie flies its firmware's controller: hover, the 1.1 m/s clamp, half a second behind",
          "[quadrotor][flight][crazyflie]") {
  // the installed crazyflie (an X frame, 29 g, 65 ms motors, Bitcraze's thrust coefficient), noise off
  Scene s = quadScene("<sensor index=\"0\" noise=\"false\"/><sensor index=\"1\" position_noise=\"0\" velocity_noise=\"0\"/>"
                      "<driver reference=\"external\"/>",
                      1.0, 3, "crazyflie");
  Environment& env = *s.environment;
  env.start();
  Artifact& cf = *env.findArtifact("quad");
  auto* input = dynamic_cast<CommandInterface*>(cf.driver());
  REQUIRE(input != nullptr);
  CHECK(input->acceptsCommand(CommandLevel::Velocity));
  CHECK(input->acceptsCommand(CommandLevel::Rotors));  // (the firmware's loops resting)
  CHECK_FALSE(input->acceptsCommand(CommandLevel::Wheels));
  Setpoint sp;
  sp.position = Vec3(0, 0, 1);
  input->setSetpoint(sp);
  env.step(1500);  // 3 s of hover from a start in the air
  CHECK((cf.pose().position - sp.position).norm() < 0.02);
  // 1 m to the side: the position loop asks 2 m/s and is clamped to 1.1 (the velocity loop overshoots it a little)
  sp.position = Vec3(0, 1, 1);
  input->setSetpoint(sp);
  double fastest = 0;
  for (int i = 0; i < 2000; ++i) {
    env.step();
    fastest = std::max(fastest, cf.state().linear_velocity.head<2>().norm());
  }
  INFO("fastest " << fastest << " m/s");
  CHECK(fastest < 1.1 * 1.2);
  CHECK(fastest > 0.9);
  CHECK((cf.pose().position - sp.position).norm() < 0.03);
  // a set-point moving at 0.5 m/s along x: half a second (0.25 m) behind
  for (int i = 1; i <= 3000; ++i) {
    sp.position = Vec3(0.5 * i * 0.002, 1, 1);
    input->setSetpoint(sp);
    env.step();
  }
  const double behind = sp.position.x() - cf.pose().position.x();
  INFO("behind " << behind << " m");
  CHECK(behind == Approx(0.25).margin(0.04));
  CHECK(std::abs(cf.pose().position.y() - 1) < 0.03);
}

TEST_CASE(
    "controller=\"crazyflie_pid\" is refused while loading for a plus frame and for rates the driver cannot keep, "
    "and its Kalman filter without it",
    "[quadrotor][crazyflie]") {
  // the mk_quad is a plus frame
  CHECK_THROWS_WITH(quadScene("<driver controller=\"crazyflie_pid\"/>", 1.0, 1, "mk_quad"),
                    Catch::Contains("error: <driver>") && Catch::Contains("X frame"));
  // so is a Crazyflie's preset on plus-frame rotors, unless it is told to fly TeleKyb's controller
  const std::string plus_cf = "<scene><type name=\"q\" file=\"mk_quad.xml\"/><artifact name=\"q\" type=\"q\" "
                              "xyz=\"0 0 1\"><driver preset=\"crazyflie\"{}/></artifact></scene>";
  auto with = [&](const std::string& extra) {
    std::string xml = plus_cf;
    return loadSceneFromString(xml.replace(xml.find("{}"), 2, extra), "plus_cf.xml", kArtifacts);
  };
  CHECK_THROWS_WITH(with(""), Catch::Contains("X frame"));
  CHECK_NOTHROW(with(" controller=\"telekyb\""));
  const std::string slow = "<scene><environment timestep=\"0.02\"/><type name=\"q\" file=\"mk_quad.xml\"/>"
                           "<artifact name=\"q\" type=\"q\" xyz=\"0 0 1\"><driver controller=\"crazyflie_pid\" inner_rate_hz=\"50\"/>"
                           "</artifact></scene>";
  CHECK_THROWS_WITH(loadSceneFromString(slow, "slow.xml", kArtifacts),
                    Catch::Contains("crazyflie_attitude_rate_hz: its period must be a whole multiple of the driver's"));
  // the same slow scene with TeleKyb's controller: its rates are not asked about
  const std::string telekyb = "<scene><environment timestep=\"0.02\"/><type name=\"q\" file=\"mk_quad.xml\"/>"
                              "<artifact name=\"q\" type=\"q\" xyz=\"0 0 1\"><driver inner_rate_hz=\"50\"/></artifact></scene>";
  CHECK_NOTHROW(loadSceneFromString(telekyb, "slow.xml", kArtifacts));
  // the firmware's Kalman filter belongs to its controller
  CHECK_THROWS_WITH(quadScene("<driver crazyflie_estimator=\"kalman\"/>", 1.0, 1, "mk_quad"),
                    Catch::Contains("error: <driver>") && Catch::Contains("fly controller=\"crazyflie_pid\" with it"));
}

TEST_CASE("the crazyflie's 1S battery: its firmware holds the thrust while the voltage sags, until it cannot",
          "[quadrotor][flight][crazyflie]") {
  auto heightAfter = [](const std::string& battery, double seconds) {
    Scene s = quadScene("<sensor index=\"0\" noise=\"false\"/><sensor index=\"1\" position_noise=\"0\" velocity_noise=\"0\"/>"
                        "<driver battery=\"true\" " + battery + "/>",
                        1.0, 3, "crazyflie");
    s.environment->step(static_cast<std::int64_t>(seconds / 0.002));
    return s.environment->findArtifact("quad")->pose().position.z();
  };
  // full, and nearly empty (3.2 V open circuit, sagging under the hover's current): the compensation
  // turns the same commands into the same newtons, so the hover holds
  CHECK(heightAfter("", 10) == Approx(1.0).margin(0.02));
  CHECK(heightAfter("battery_initial_charge=\"0\"", 10) == Approx(1.0).margin(0.02));
  // a pack that sags below the 2.4 V a hovering motor needs cannot be compensated: the vehicle sinks
  CHECK(heightAfter("battery_initial_charge=\"0\" battery_resistance=\"1\"", 3) < 0.5);
  // the compensation is the firmware's: TeleKyb's controller would fly the pack uncompensated
  CHECK_THROWS_WITH(quadScene("<driver battery=\"true\" controller=\"telekyb\"/>", 1.0, 1, "crazyflie"),
                    Catch::Contains("error: <driver>") && Catch::Contains("compensated by the flight controller"));
}

TEST_CASE("a crazyflie with its battery, saved mid-flight and restored, continues bitwise", "[quadrotor][crazyflie][determinism]") {
  auto scene = [] { return quadScene("<driver battery=\"true\" offset=\"0.5 0 0\"/>", 1.0, 7, "crazyflie"); };
  Scene a = scene(), b = scene();
  a.environment->step(700);
  b.environment->step(700);
  const auto saved = a.environment->saveState();
  a.environment->step(800);
  Scene c = scene();
  c.environment->restoreState(saved);
  c.environment->step(800);
  b.environment->step(800);
  CHECK(c.environment->stateHash() == a.environment->stateHash());
  CHECK(b.environment->stateHash() == a.environment->stateHash());
}

TEST_CASE("a vehicle from a preset file: by name from the artifact path, or by path, and the element's values win",
          "[quadrotor][presets]") {
  std::string pattern = (std::filesystem::temp_directory_path() / "ssx_quad_presets_XXXXXX").string();
  REQUIRE(mkdtemp(pattern.data()) != nullptr);
  const std::filesystem::path dir = pattern;
  std::filesystem::create_directories(dir / "presets" / "quadrotor");
  // motors too weak to carry the mk_quad's 0.82 kg (hover needs 448 rad/s)
  std::ofstream(dir / "presets" / "quadrotor" / "weak.xml")
      << "<preset class=\"quadrotor\">\n  <param name=\"max_rotor_speed\" value=\"300\"/>\n</preset>\n";
  SceneOptions options;
  options.artifact_path = {dir};
  auto heightAfter = [&](const std::string& driver, std::uint64_t* hash = nullptr) {
    const std::string xml = "<scene><environment timestep=\"0.002\" seed=\"3\"/><type name=\"q\" file=\"mk_quad.xml\"/>"
                            "<ground/><artifact name=\"quad\" type=\"q\" xyz=\"0 0 2\">" +
                            driver + "</artifact></scene>";
    Scene s = loadSceneFromString(xml, "quad.xml", kArtifacts, options);
    s.environment->step(500);  // 1 s
    if (hash != nullptr) *hash = s.environment->stateHash();
    return s.environment->findArtifact("quad")->pose().position.z();
  };
  std::uint64_t plain = 0, named = 0, by_path = 0;
  CHECK(std::abs(heightAfter("", &plain) - 2) < 0.02);
  // the installed mk_quad preset is the default written out: the same bits
  (void)heightAfter("<driver preset=\"mk_quad\"/>", &named);
  CHECK(named == plain);
  (void)heightAfter("<driver preset=\"" + (kArtifacts.parent_path() / "presets/quadrotor/mk_quad.xml").string() + "\"/>",
                    &by_path);
  CHECK(by_path == plain);
  // the user's weak motors: it falls (1 s of free fall is 4.9 m; it is on the ground)
  CHECK(heightAfter("<driver preset=\"weak\"/>") < 0.5);
  // unless the element gives its own
  CHECK(std::abs(heightAfter("<driver preset=\"weak\" max_rotor_speed=\"940\"/>") - 2) < 0.02);
  std::filesystem::remove_all(dir);
}

TEST_CASE("a crazyflie flying on its firmware's Kalman filter: hovers, moves, and its estimate follows the truth",
          "[quadrotor][flight][crazyflie]") {
  // the IMU's noise and the motion capture's as installed: the filter between them and the loops
  Scene s = quadScene("<driver reference=\"external\" crazyflie_estimator=\"kalman\"/>", 1.0, 5, "crazyflie");
  Environment& env = *s.environment;
  env.start();
  Artifact& cf = *env.findArtifact("quad");
  auto* input = dynamic_cast<SetpointInterface*>(cf.driver());
  REQUIRE(input != nullptr);
  Setpoint sp;
  sp.position = Vec3(0, 0, 1);
  input->setSetpoint(sp);
  env.step(1500);
  INFO("hover error " << (cf.pose().position - sp.position).transpose());
  CHECK((cf.pose().position - sp.position).norm() < 0.03);
  sp.position = Vec3(0.5, 0.5, 1.2);
  input->setSetpoint(sp);
  env.step(2000);
  INFO("error " << (cf.pose().position - sp.position).transpose());
  CHECK((cf.pose().position - sp.position).norm() < 0.03);
}

TEST_CASE("a crazyflie on its Kalman filter flies bitwise alike on 1 and 2 threads and after a saved state",
          "[quadrotor][crazyflie][determinism]") {
  auto scene = [](int threads) {
    SceneOptions o;
    o.threads = threads;
    const std::string xml =
        "<scene><environment timestep=\"0.002\" seed=\"9\"/><type name=\"q\" file=\"crazyflie.xml\"/><ground/>"
        "<artifact name=\"a\" type=\"q\" xyz=\"0 0 1\"><driver crazyflie_estimator=\"kalman\" offset=\"0.5 0 "
        "0\"/></artifact>"
        "<artifact name=\"b\" type=\"q\" xyz=\"2 0 1\"><driver crazyflie_estimator=\"kalman\" offset=\"0 0.5 "
        "0\"/></artifact>"
        "</scene>";
    return loadSceneFromString(xml, "kalman.xml", kArtifacts, o);
  };
  Scene a = scene(1), b = scene(2);
  a.environment->step(700);
  b.environment->step(700);
  const auto saved = a.environment->saveState();
  a.environment->step(800);
  b.environment->step(800);
  Scene c = scene(1);
  c.environment->restoreState(saved);
  c.environment->step(800);
  CHECK(c.environment->stateHash() == a.environment->stateHash());
  CHECK(b.environment->stateHash() == a.environment->stateHash());
}
