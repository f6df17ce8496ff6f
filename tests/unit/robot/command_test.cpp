// Commands at the five levels (ssx/command.hpp): names, rows, and what is wrong with a command
// whatever the vehicle. Vehicles taking them: tests/unit/quadrotor/telekyb_controller_test.cpp.
#include <ssx/command.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace ssx;

TEST_CASE("command levels have names and rows of known sizes", "[command]") {
  for (CommandLevel level : kCommandLevels) CHECK(commandLevelFromName(commandLevelName(level)) == level);
  CHECK_FALSE(commandLevelFromName("thrust").has_value());
  CHECK(Command::rowSizeFits(CommandLevel::Position, 4, 4));
  CHECK(Command::rowSizeFits(CommandLevel::Position, 11, 4));
  CHECK_FALSE(Command::rowSizeFits(CommandLevel::Position, 5, 4));
  CHECK_FALSE(Command::rowSizeFits(CommandLevel::Velocity, 3, 4));
  CHECK(Command::rowSizeFits(CommandLevel::Rotors, 6, 6));
  CHECK_FALSE(Command::rowSizeFits(CommandLevel::Rotors, 4, 6));
  const double row[] = {1, 2, 3, 0.5, 4, 5, 6};
  const Command c = Command::fromRow(CommandLevel::Position, row);
  CHECK(c.setpoint.position == Vec3(1, 2, 3));
  CHECK(c.setpoint.yaw == 0.5);
  CHECK(c.setpoint.velocity == Vec3(4, 5, 6));
  CHECK(c.setpoint.acceleration == Vec3::Zero());
  const double att[] = {0.1, -0.2, 0.3, 7};
  const Command a = Command::fromRow(CommandLevel::Attitude, att);
  CHECK((a.roll == 0.1 && a.pitch == -0.2 && a.yaw_rate == 0.3 && a.thrust == 7));
  CHECK(Command::attitude(0, 0, 0, -1).problem().find("negative") != std::string::npos);
  CHECK(Command::attitude(1.5, 0, 0, 1).problem().find("80 degrees") != std::string::npos);
  CHECK(Command::rates(Vec3(0, NAN, 0), 1).problem().find("NaN") != std::string::npos);
  CHECK(Command::rotors({400, -1, 400, 400}).problem().find("magnitudes") != std::string::npos);
  CHECK(Command::velocityYawRate(Vec3(1, 0, 0), 0.1).problem().empty());
  CHECK(Command::wheels(1, NAN).problem().find("NaN") != std::string::npos);
  CHECK(Command::wheels(-3, 3).problem().empty());  // backwards is a direction, not a fault
  CHECK(Command::rowSizeFits(CommandLevel::Wheels, 2, 0));
  CHECK_FALSE(Command::rowSizeFits(CommandLevel::Wheels, 4, 0));
}

TEST_CASE("a command's row is the row it was read from (position: all 11 columns)", "[command]") {
  const std::vector<std::vector<double>> rows{{1, 2, 3, 0.5, 4, 5, 6, 7, 8, 9, 0.25}, {0.5, -1, 0.25, 0.1},
                                              {0.1, -0.2, 0.3, 7}, {1, -2, 3, 9.5}, {400, 410.5, 420, 430},
                                              {6.5, -2.25}};
  for (std::size_t i = 0; i < rows.size(); ++i) {
    INFO(commandLevelName(kCommandLevels[i]));
    CHECK(Command::fromRow(kCommandLevels[i], rows[i]).toRow() == rows[i]);
  }
  const double short_position[] = {1, 2, 3, 0.5};
  CHECK(Command::fromRow(CommandLevel::Position, short_position).toRow() ==
        std::vector<double>{1, 2, 3, 0.5, 0, 0, 0, 0, 0, 0, 0});
}

TEST_CASE("a command as JSON: its level's name and its row", "[command]") {
  CHECK(commandJson(Command::velocityYawRate(Vec3(0.5, -1, 0.25), 0.1)) ==
        R"({"level":"velocity","values":[0.5,-1,0.25,0.1]})");
  CHECK(commandJson(Command::rotors({400, 410.5})) == R"({"level":"rotors","values":[400,410.5]})");
}

TEST_CASE("a command holding a value beyond 1e6 is refused whatever the level, with the value", "[command]") {
  CHECK(Command::velocityYawRate(Vec3(1e6, 0, 0)).problem().empty());
  CHECK_THAT(Command::velocityYawRate(Vec3(0, 1e300, 0)).problem(),
             Catch::Contains("a velocity command holds 1e+300, beyond any command"));
  CHECK_THAT(Command::velocityYawRate(Vec3::Zero(), -2e6).problem(), Catch::Contains("holds -2e+06"));
  Command far;
  far.level = CommandLevel::Position;
  far.setpoint.position = Vec3(0, 0, 1e7);
  CHECK_THAT(far.problem(), Catch::Contains("a position command holds 1e+07"));
  Command wheels;
  wheels.level = CommandLevel::Wheels;
  wheels.left_wheel = 1e9;
  CHECK_FALSE(wheels.problem().empty());
  // not finite is said as before
  CHECK_THAT(Command::velocityYawRate(Vec3(NAN, 0, 0)).problem(), Catch::Contains("NaN or an infinity"));
}
