// The TeleKyb controller commanded at each of the five command levels, in a quadrotor loaded as a
// user's scene loads it.
#include "quadrotor_model.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

using namespace ssx;

namespace {

const std::filesystem::path kArtifacts = std::filesystem::path(SSX_EXAMPLES_DIR) / "artifacts";

// one mk_quad hovering at 1 m, noiseless sensors, its driver taking external commands
struct Flight {
  Scene scene;
  Environment& env;
  Artifact& quad;
  CommandInterface& input;
  double mass, g;

  explicit Flight(const std::string& driver = "", const std::string& type = "mk_quad")
      : scene(loadSceneFromString(
            "<scene><environment timestep=\"0.002\" seed=\"3\"/><type name=\"q\" file=\"" + type +
                ".xml\"/><ground/><artifact name=\"quad\" type=\"q\" xyz=\"0 0 1\"><driver reference=\"external\" " +
                driver + "/><sensor index=\"0\" noise=\"false\"/><sensor index=\"1\" position_noise=\"0\" "
                         "velocity_noise=\"0\"/></artifact></scene>",
            "commands.xml", kArtifacts)),
        env(*scene.environment),
        quad(*env.findArtifact("quad")),
        input(dynamic_cast<CommandInterface&>(*quad.driver())),
        mass(combinedMass(quad.root().spec()).mass),
        g(-env.settings().physics.gravity.z()) {
    env.step(500);  // settled at its placed hover point
  }
  Vec3 position() const { return quad.pose().position; }
  Vec3 velocity() const { return quad.state().linear_velocity; }
};

}  // namespace

TEST_CASE("a refused command leaves the quadrotor as it was", "[quadrotor][commands]") {
  Flight f;
  f.input.setCommand(Command::velocityYawRate(Vec3(0.5, 0, 0)));
  CHECK_THROWS_AS(f.input.setCommand(Command::rotors({400, 400, 400})), std::invalid_argument);
  CHECK_THROWS_WITH(f.input.setCommand(Command::rotors({400, 400, 400})), Catch::Contains("one speed per rotor: 4"));
  CHECK_THROWS_AS(f.input.setCommand(Command::attitude(0, 0, NAN, f.mass * f.g)), std::invalid_argument);
  CHECK(f.input.commandLevel() == CommandLevel::Velocity);
  CHECK(f.input.rotorCount() == 4);
}

TEST_CASE("attitude level: level attitude at thrust m g holds the vehicle level, its height follows the motors' resolution",
          "[quadrotor][commands]") {
  // The mk_quad's motors take 8-bit commands, so m g is delivered as the thrust of the nearest
  // commandable speed: the vehicle climbs or sinks at the constant acceleration that rounding makes
  // (0.06 m/s^2 up for the mk_quad: 0.7 m in 5 s). Its attitude is held level throughout.
  Flight f;
  const quadrotor::RotorParams rp = quadrotor::RotorParams{};
  const double step = rp.max_rotor_speed / 255.0;
  const double exact = std::sqrt(f.mass * f.g / (4 * rp.thrust_coefficient));
  const double commanded = std::round(exact / step) * step;
  const double accel = f.g * (commanded * commanded / (exact * exact) - 1.0);
  const Vec3 start = f.position();
  f.input.setCommand(Command::attitude(0, 0, 0, f.mass * f.g));
  CHECK(f.input.commandLevel() == CommandLevel::Attitude);
  double sideways = 0, worst_tilt = 0;
  for (int i = 0; i < 2500; ++i) {  // 5 s
    f.env.step();
    sideways = std::max(sideways, (f.position() - start).head<2>().norm());
    worst_tilt = std::max(worst_tilt, std::acos(std::min(1.0, (f.quad.pose().orientation * Vec3::UnitZ()).z())));
  }
  const double climbed = f.position().z() - start.z();
  INFO("sideways " << sideways << " m, tilt " << worst_tilt << " rad, climbed " << climbed << " m, rounding predicts "
                   << 0.5 * accel * 25.0 << " m");
  CHECK(sideways < 0.02);
  CHECK(worst_tilt < 0.01);
  CHECK(std::abs(climbed - 0.5 * accel * 25.0) < 0.05);
}

TEST_CASE("attitude level: a roll command accelerates the vehicle to the correct side", "[quadrotor][commands]") {
  // a positive roll turns the body's z axis towards -y (right-handed about x)
  for (double roll : {0.1, -0.1}) {
    Flight f;
    const Vec3 start = f.position();
    f.input.setCommand(Command::attitude(roll, 0, 0, f.mass * f.g / std::cos(roll)));
    f.env.step(250);  // 0.5 s
    const Vec3 moved = f.position() - start;
    INFO("roll " << roll << " moved " << moved.transpose());
    CHECK(moved.y() * roll < 0);
    CHECK(std::abs(moved.y()) > 0.05);
    CHECK(std::abs(moved.x()) < 0.3 * std::abs(moved.y()));
  }
}

TEST_CASE("rates level: a roll rate turns the vehicle at that rate", "[quadrotor][commands]") {
  Flight f;
  f.input.setCommand(Command::rates(Vec3(0.5, 0, 0), f.mass * f.g));
  f.env.step(100);  // 0.2 s to take up the rate
  const double p = (f.quad.pose().orientation.conjugate() * f.quad.state().angular_velocity).x();
  INFO("body roll rate " << p);
  CHECK(std::abs(p - 0.5) < 0.05);
  // zero rates hold whatever attitude it has (no pull back to level)
  f.input.setCommand(Command::rates(Vec3::Zero(), f.mass * f.g));
  f.env.step(100);
  const Vec3 up = f.quad.pose().orientation * Vec3::UnitZ();
  const double held = std::atan2(-up.y(), up.z());
  f.env.step(100);
  const Vec3 up2 = f.quad.pose().orientation * Vec3::UnitZ();
  INFO("roll after the rate " << held);
  CHECK(held > 0.08);
  CHECK(std::abs(std::atan2(-up2.y(), up2.z()) - held) < 0.01);
}

TEST_CASE("rotors level: every rotor at the hover speed holds altitude", "[quadrotor][commands]") {
  Flight f;
  const Vec3 start = f.position();
  // the speed at which four rotors carry the weight, from the vehicle's own thrust coefficient
  const double kf = 1.0e-5;  // mk_quad's (examples/artifacts/mk_quad.xml uses the preset's)
  const double hover = std::sqrt(f.mass * f.g / (4 * kf));
  f.input.setCommand(Command::rotors({hover, hover, hover, hover}));
  CHECK(f.input.commandLevel() == CommandLevel::Rotors);
  double worst = 0;
  for (int i = 0; i < 1000; ++i) {  // 2 s
    f.env.step();
    worst = std::max(worst, std::abs(f.position().z() - start.z()));
  }
  INFO("largest height change " << worst << " m");
  CHECK(worst < 0.05);
  // and a faster speed climbs
  f.input.setCommand(Command::rotors({1.1 * hover, 1.1 * hover, 1.1 * hover, 1.1 * hover}));
  f.env.step(250);
  CHECK(f.position().z() > start.z() + 0.1);
}

TEST_CASE("velocity level: reaches 1 m/s and holds it, then stops", "[quadrotor][commands]") {
  Flight f;
  f.input.setCommand(Command::velocityYawRate(Vec3(1, 0, 0)));
  f.env.step(1500);  // 3 s
  double slowest = 1e9, fastest = 0;
  for (int i = 0; i < 500; ++i) {  // the next second
    f.env.step();
    slowest = std::min(slowest, f.velocity().x());
    fastest = std::max(fastest, f.velocity().x());
  }
  INFO("vx between " << slowest << " and " << fastest << " m/s");
  CHECK(slowest > 0.9);
  CHECK(fastest < 1.1);
  CHECK(std::abs(f.position().z() - 1.0) < 0.05);  // at its height
  f.input.setCommand(Command::velocityYawRate(Vec3::Zero()));
  f.env.step(1500);
  CHECK(f.velocity().norm() < 0.05);
}

TEST_CASE("position level after a lower level flies to the set-point again", "[quadrotor][commands]") {
  Flight f;
  f.input.setCommand(Command::attitude(0.05, 0, 0, f.mass * f.g));
  f.env.step(250);
  Setpoint sp;
  sp.position = Vec3(0.5, 0.5, 1.5);
  f.input.setSetpoint(sp);
  CHECK(f.input.commandLevel() == CommandLevel::Position);
  f.env.step(3000);
  CHECK((f.position() - sp.position).norm() < 0.05);
}

TEST_CASE("a command level and its command survive save and restore bitwise", "[quadrotor][commands][state]") {
  for (CommandLevel level : {CommandLevel::Velocity, CommandLevel::Attitude, CommandLevel::Rates, CommandLevel::Rotors}) {
    INFO(commandLevelName(level));
    Flight f;
    const double hover = std::sqrt(f.mass * f.g / 4e-5);
    const Command commands[] = {Command::velocityYawRate(Vec3(0.3, -0.2, 0.1), 0.2),
                                Command::attitude(0.05, -0.03, 0.1, f.mass * f.g),
                                Command::rates(Vec3(0.1, 0, -0.1), f.mass * f.g),
                                Command::rotors({hover, hover * 1.01, hover, hover * 0.99})};
    f.input.setCommand(commands[static_cast<std::size_t>(level) - 1]);
    f.env.step(100);
    const auto saved = f.env.saveState();
    f.env.step(200);
    const Pose expected = f.quad.pose();
    Flight g;
    g.env.restoreState(saved);
    CHECK(g.input.commandLevel() == level);
    g.env.step(200);
    CHECK(g.quad.pose().position == expected.position);
    CHECK(g.quad.pose().orientation.coeffs() == expected.orientation.coeffs());
  }
}

TEST_CASE("the current command is the one taken, at every level (rates in the inner loop's steps)",
          "[quadrotor][commands]") {
  Flight f;
  // position: the set-point tracked
  CHECK(f.input.currentCommand().level == CommandLevel::Position);
  CHECK(f.input.currentCommand().setpoint.position.isApprox(f.input.currentSetpoint().position));
  const std::vector<Command> commands{Command::velocityYawRate(Vec3(0.5, -0.25, 0.1), 0.2),
                                      Command::attitude(0.05, -0.1, 0.3, f.mass * f.g),
                                      Command::rates(Vec3(0.5, -0.25, 0.125), f.mass * f.g),
                                      Command::rotors({400, 410, 420, 430})};
  for (const Command& c : commands) {
    INFO(commandLevelName(c.level));
    f.input.setCommand(c);
    f.env.step(1);
    const Command now = f.input.currentCommand();
    CHECK(now.level == c.level);
    const std::vector<double> want = c.toRow(), got = now.toRow();
    REQUIRE(got.size() == want.size());
    for (std::size_t k = 0; k < want.size(); ++k) CHECK(got[k] == Approx(want[k]).margin(1.0 / 4096));
  }
}
