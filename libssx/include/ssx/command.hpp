#pragma once
/// @file
/// Command levels: how a program, a bridge or a viewer commands a vehicle, from a position with
/// feed-forward down to each rotor's speed (as PX4's offboard mode and gym-pybullet-drones do).
/// Drivers that take commands implement CommandInterface; anyone finds it with
/// `dynamic_cast<ssx::CommandInterface*>(artifact.driver())`.
///
/// | level      | values (the column order of Python's `Environment.set_commands`)               |
/// |------------|---------------------------------------------------------------------------------|
/// | `position` | x, y, z (m), yaw (rad); optionally vx, vy, vz (m/s), ax, ay, az (m/s^2), yaw rate (rad/s) |
/// | `velocity` | vx, vy, vz (m/s, world frame), yaw rate (rad/s)                                  |
/// | `attitude` | roll, pitch (rad), yaw rate (rad/s), collective thrust (N)                        |
/// | `rates`    | body rates p, q, r (rad/s), collective thrust (N)                                 |
/// | `rotors`   | each rotor's speed (rad/s), one column per rotor                                  |
/// | `wheels`   | a differential drive's left and right wheel speeds (rad/s, positive: forward)     |
///
/// A ground robot takes `velocity` as a forward speed and a yaw rate: the velocity's component
/// along its heading when the command is given, and the yaw rate.
///
/// A command holds until the next one (zero-order hold).

#include <ssx/export.hpp>
#include <ssx/setpoint.hpp>
#include <ssx/types.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace ssx {

/// A command level, from the highest (position with feed-forward) to the lowest (rotor speeds),
/// then a ground robot's wheel speeds; the table above lists each level's values.
enum class CommandLevel : std::uint8_t { Position, Velocity, Attitude, Rates, Rotors, Wheels };

/// The six levels: a flying vehicle's five, from the highest to the lowest, then a ground robot's wheels.
inline constexpr CommandLevel kCommandLevels[] = {CommandLevel::Position, CommandLevel::Velocity,
                                                  CommandLevel::Attitude, CommandLevel::Rates,
                                                  CommandLevel::Rotors,   CommandLevel::Wheels};

/// "position", "velocity", "attitude", "rates", "rotors" or "wheels".
SSX_EXPORT const char* commandLevelName(CommandLevel level);
/// The level of that name; nothing for another name.
SSX_EXPORT std::optional<CommandLevel> commandLevelFromName(std::string_view name);

struct Command;
/// A command as a JSON object: `{"level":"velocity","values":[...]}`, the values in the column
/// order of Python's set_commands (Command::toRow), as the recorder's `/ssx/commands` channel and
/// the viewer have it.
SSX_EXPORT std::string commandJson(const Command& command);

/// One command at one level; only the fields of its level are read.
struct SSX_EXPORT Command {
  CommandLevel level = CommandLevel::Position;  ///< which of the fields below are read
  Setpoint setpoint;                ///< position: where, its feed-forward and heading
  Vec3 velocity = Vec3::Zero();     ///< velocity: m/s, world frame
  double yaw_rate = 0;              ///< velocity, attitude: rad/s
  double roll = 0;                  ///< attitude: rad
  double pitch = 0;                 ///< attitude: rad
  Vec3 body_rates = Vec3::Zero();   ///< rates: p, q, r in rad/s, body frame
  double thrust = 0;                ///< attitude, rates: collective thrust, N
  std::vector<double> rotor_speeds;  ///< rotors: rad/s, one per rotor
  double left_wheel = 0;             ///< wheels: rad/s, positive: forward
  double right_wheel = 0;            ///< wheels: rad/s, positive: forward

  /// A position command: the set-point's position, feed-forward and heading.
  static Command position(const Setpoint& setpoint);
  /// A velocity command: m/s in the world frame and a yaw rate in rad/s.
  static Command velocityYawRate(const Vec3& velocity, double yaw_rate = 0);
  /// An attitude command: roll and pitch in rad, yaw rate in rad/s, collective thrust in N.
  static Command attitude(double roll, double pitch, double yaw_rate, double thrust);
  /// A body-rate command: p, q, r in rad/s (body frame) and collective thrust in N.
  static Command rates(const Vec3& body_rates, double thrust);
  /// A rotor command: each rotor's speed in rad/s, in the vehicle's rotor order.
  static Command rotors(std::vector<double> speeds);

  /// A wheels command: a differential drive's left and right wheel speeds, rad/s.
  static Command wheels(double left, double right);
  /// The numbers of values a row of this level may have: position 4, 7, 10 or 11 (a prefix of
  /// the columns above, the rest zero), velocity, attitude and rates 4, rotors `rotor_count`,
  /// wheels 2.
  static bool rowSizeFits(CommandLevel level, std::size_t size, std::size_t rotor_count);
  /// What rowSizeFits accepts, in words ("4, 7, 10 or 11").
  static std::string rowSizes(CommandLevel level, std::size_t rotor_count);
  /// A command from one row in the column order above (its size as rowSizeFits accepts).
  static Command fromRow(CommandLevel level, std::span<const double> row);
  /// Its values as one row in the column order above (position: all 11), as fromRow reads them.
  std::vector<double> toRow() const;

  /// What is wrong with it whatever the vehicle (a value not finite or beyond kMaxCommandValue, a
  /// negative thrust or rotor speed, a roll or pitch beyond 80 degrees), or an empty string.
  std::string problem() const;
};

/// The largest magnitude any value of a command may have (m, m/s, m/s^2, rad/s, N): a position
/// 1,000 km away, a speed of 1,000 km/s. Beyond it a value is a corrupted or hostile message, not
/// a command (and squared, as controllers do, it would overflow to infinity).
inline constexpr double kMaxCommandValue = 1e6;

/// Implemented by drivers that take commands at one or more levels. Call only between steps, or
/// from an extension's hooks, never from another artifact's driver or sensor (the parallel phases).
class SSX_EXPORT CommandInterface : public SetpointInterface {
 public:
  ~CommandInterface() override;
  /// Whether this driver takes commands at `level`.
  virtual bool acceptsCommand(CommandLevel level) const = 0;
  /// The rotors a `rotors` command must name (0 for a vehicle without rotors).
  virtual std::size_t rotorCount() const = 0;
  /// What is wrong with this command for this driver (a level it does not take, the wrong number
  /// of rotors, Command::problem()), or an empty string.
  std::string refusal(const Command& command) const;
  /// refusal() for a driver that takes the command's level or not (`accepts`) and has `rotors`
  /// rotors: for a caller that asked the driver once (a learning batch's copies of one robot).
  static std::string refusal(const Command& command, bool accepts, std::size_t rotors);
  /// Switches the driver to this command, held until the next one. Throws std::invalid_argument
  /// with refusal()'s message, leaving the driver as it was, for a command it refuses.
  virtual void setCommand(const Command& command) = 0;
  /// The level of the latest command (position while a reference of the scene's drives it).
  virtual CommandLevel commandLevel() const = 0;
  /// The command followed now: at the position level the set-point tracked (currentSetpoint: a
  /// scene's reference moves it), at the others the latest command as the vehicle took it. This
  /// default knows only the level and the set-point; drivers that keep lower levels' values say them.
  virtual Command currentCommand() const;
  /// A set-point is a command at the position level.
  void setSetpoint(const Setpoint& setpoint) override { setCommand(Command::position(setpoint)); }
};

}  // namespace ssx
