#include "base/json.hpp"

#include <ssx/command.hpp>
#include <ssx/odometry.hpp>
#include <ssx/operator.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace ssx {

namespace {

constexpr const char* kNames[] = {"position", "velocity", "attitude", "rates", "rotors", "wheels"};
// the attitude estimate of a vehicle's inner loop holds pitch within +-80 degrees
constexpr double kMaxAngle = 80.0 * std::numbers::pi / 180.0;

bool finite(const Vec3& v) { return v.allFinite(); }

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

}  // namespace

const char* commandLevelName(CommandLevel level) { return kNames[static_cast<std::size_t>(level)]; }

std::optional<CommandLevel> commandLevelFromName(std::string_view name) {
  for (CommandLevel level : kCommandLevels)
    if (name == kNames[static_cast<std::size_t>(level)]) return level;
  return std::nullopt;
}

Command Command::position(const Setpoint& setpoint) {
  Command c;
  c.level = CommandLevel::Position;
  c.setpoint = setpoint;
  return c;
}

Command Command::velocityYawRate(const Vec3& velocity, double yaw_rate) {
  Command c;
  c.level = CommandLevel::Velocity;
  c.velocity = velocity;
  c.yaw_rate = yaw_rate;
  return c;
}

Command Command::attitude(double roll, double pitch, double yaw_rate, double thrust) {
  Command c;
  c.level = CommandLevel::Attitude;
  c.roll = roll;
  c.pitch = pitch;
  c.yaw_rate = yaw_rate;
  c.thrust = thrust;
  return c;
}

Command Command::rates(const Vec3& body_rates, double thrust) {
  Command c;
  c.level = CommandLevel::Rates;
  c.body_rates = body_rates;
  c.thrust = thrust;
  return c;
}

Command Command::rotors(std::vector<double> speeds) {
  Command c;
  c.level = CommandLevel::Rotors;
  c.rotor_speeds = std::move(speeds);
  return c;
}

Command Command::wheels(double left, double right) {
  Command c;
  c.level = CommandLevel::Wheels;
  c.left_wheel = left;
  c.right_wheel = right;
  return c;
}

bool Command::rowSizeFits(CommandLevel level, std::size_t size, std::size_t rotor_count) {
  switch (level) {
    case CommandLevel::Position:
      return size == 4 || size == 7 || size == 10 || size == 11;
    case CommandLevel::Rotors:
      return size == rotor_count && size > 0;
    case CommandLevel::Wheels:
      return size == 2;
    default:
      return size == 4;
  }
}

std::string Command::rowSizes(CommandLevel level, std::size_t rotor_count) {
  switch (level) {
    case CommandLevel::Position:
      return "4 (x, y, z, yaw), 7 (and vx, vy, vz), 10 (and ax, ay, az) or 11 (and the yaw rate)";
    case CommandLevel::Velocity:
      return "4 (vx, vy, vz, yaw rate)";
    case CommandLevel::Attitude:
      return "4 (roll, pitch, yaw rate, thrust)";
    case CommandLevel::Rates:
      return "4 (p, q, r, thrust)";
    case CommandLevel::Rotors:
      return std::to_string(rotor_count) + " (one speed per rotor)";
    case CommandLevel::Wheels:
      return "2 (left, right wheel speed)";
  }
  return {};
}

Command Command::fromRow(CommandLevel level, std::span<const double> r) {
  const auto at = [&](std::size_t i) { return i < r.size() ? r[i] : 0.0; };
  switch (level) {
    case CommandLevel::Position: {
      Setpoint s;
      s.position = Vec3(at(0), at(1), at(2));
      s.yaw = at(3);
      s.velocity = Vec3(at(4), at(5), at(6));
      s.acceleration = Vec3(at(7), at(8), at(9));
      s.yaw_rate = at(10);
      return position(s);
    }
    case CommandLevel::Velocity:
      return velocityYawRate(Vec3(at(0), at(1), at(2)), at(3));
    case CommandLevel::Attitude:
      return attitude(at(0), at(1), at(2), at(3));
    case CommandLevel::Rates:
      return rates(Vec3(at(0), at(1), at(2)), at(3));
    case CommandLevel::Rotors:
      return rotors(std::vector<double>(r.begin(), r.end()));
    case CommandLevel::Wheels:
      return wheels(at(0), at(1));
  }
  return {};
}

std::vector<double> Command::toRow() const {
  switch (level) {
    case CommandLevel::Position: {
      const Setpoint& p = setpoint;
      return {p.position.x(),     p.position.y(),     p.position.z(),     p.yaw,
              p.velocity.x(),     p.velocity.y(),     p.velocity.z(),     p.acceleration.x(),
              p.acceleration.y(), p.acceleration.z(), p.yaw_rate};
    }
    case CommandLevel::Velocity:
      return {velocity.x(), velocity.y(), velocity.z(), yaw_rate};
    case CommandLevel::Attitude:
      return {roll, pitch, yaw_rate, thrust};
    case CommandLevel::Rates:
      return {body_rates.x(), body_rates.y(), body_rates.z(), thrust};
    case CommandLevel::Rotors:
      return rotor_speeds;
    case CommandLevel::Wheels:
      return {left_wheel, right_wheel};
  }
  return {};
}

std::string Command::problem() const {
  // (no allocation: a batch of commands is checked one by one)
  double largest = 0;
  const auto look = [&largest](double v) {
    if (std::isfinite(v) && std::abs(v) > std::abs(largest)) largest = v;
  };
  const auto look3 = [&look](const Vec3& v) { look(v.x()), look(v.y()), look(v.z()); };
  switch (level) {
    case CommandLevel::Position:
      look3(setpoint.position), look3(setpoint.velocity), look3(setpoint.acceleration);
      look(setpoint.yaw), look(setpoint.yaw_rate);
      break;
    case CommandLevel::Velocity: look3(velocity), look(yaw_rate); break;
    case CommandLevel::Attitude: look(roll), look(pitch), look(yaw_rate), look(thrust); break;
    case CommandLevel::Rates: look3(body_rates), look(thrust); break;
    case CommandLevel::Rotors:
      for (const double w : rotor_speeds) look(w);
      break;
    case CommandLevel::Wheels: look(left_wheel), look(right_wheel); break;
  }
  if (std::abs(largest) > kMaxCommandValue)
    return std::string("a ") + commandLevelName(level) + " command holds " + number(largest) +
           ", beyond any command (at most 1e6 in magnitude)";
  switch (level) {
    case CommandLevel::Position:
      if (!finite(setpoint.position) || !finite(setpoint.velocity) || !finite(setpoint.acceleration) ||
          !std::isfinite(setpoint.yaw) || !std::isfinite(setpoint.yaw_rate))
        return "a position command holds a NaN or an infinity";
      return {};
    case CommandLevel::Velocity:
      if (!finite(velocity) || !std::isfinite(yaw_rate)) return "a velocity command holds a NaN or an infinity";
      return {};
    case CommandLevel::Attitude:
      if (!std::isfinite(roll) || !std::isfinite(pitch) || !std::isfinite(yaw_rate) || !std::isfinite(thrust))
        return "an attitude command holds a NaN or an infinity";
      if (std::abs(roll) > kMaxAngle || std::abs(pitch) > kMaxAngle)
        return "an attitude command's roll and pitch must be within +-80 degrees (+-1.396 rad), got roll " +
               number(roll) + ", pitch " + number(pitch);
      break;
    case CommandLevel::Rates:
      if (!finite(body_rates) || !std::isfinite(thrust)) return "a rates command holds a NaN or an infinity";
      break;
    case CommandLevel::Rotors:
      for (double w : rotor_speeds) {
        if (!std::isfinite(w)) return "a rotors command holds a NaN or an infinity";
        if (w < 0) return "rotor speeds are magnitudes (the spin direction is the rotor's), got " + number(w);
      }
      return {};
    case CommandLevel::Wheels:
      if (!std::isfinite(left_wheel) || !std::isfinite(right_wheel)) return "a wheels command holds a NaN or an infinity";
      return {};
  }
  if (thrust < 0) return "thrust must not be negative, got " + number(thrust) + " N";
  return {};
}

CommandInterface::~CommandInterface() = default;

OperatorInterface::~OperatorInterface() = default;

OdometryInterface::~OdometryInterface() = default;

Command CommandInterface::currentCommand() const {
  Command c;
  c.level = commandLevel();
  if (c.level == CommandLevel::Position) c.setpoint = currentSetpoint();
  return c;
}

std::string CommandInterface::refusal(const Command& command) const {
  return refusal(command, acceptsCommand(command.level), rotorCount());
}

std::string CommandInterface::refusal(const Command& command, bool accepts, std::size_t rotors) {
  if (!accepts)
    return std::string("this driver takes no commands at the ") + commandLevelName(command.level) + " level";
  if (command.level == CommandLevel::Rotors && command.rotor_speeds.size() != rotors)
    return "a rotors command needs one speed per rotor: " + std::to_string(rotors) + ", got " +
           std::to_string(command.rotor_speeds.size());
  return command.problem();
}

std::string commandJson(const Command& command) {
  std::string out = R"({"level":")";
  out += commandLevelName(command.level);
  out += R"(","values":[)";
  const std::vector<double> row = command.toRow();
  for (std::size_t k = 0; k < row.size(); ++k) {
    if (k > 0) out += ',';
    detail::appendNumber(out, row[k]);
  }
  return out + "]}";
}

}  // namespace ssx
