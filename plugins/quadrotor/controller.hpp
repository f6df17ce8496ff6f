#pragma once
// A rotorcraft's flight controller, behind one interface: it takes commands at the command levels
// it accepts (ssx/command.hpp) and turns them, with what it senses, into a speed for each rotor.
// The vehicle (vehicle.hpp) spins the rotors; the references (references.hpp) give position-level
// set-points. The quadrotor driver holds one controller, chosen at load (`controller`): another
// fits beside TeleKybController and CrazyfliePidController without touching the vehicle.
#include <ssx/ssx.hpp>

#include <cstdint>
#include <span>

namespace ssx::quadrotor {

/// What a controller reads while it runs, from the driver that hosts it.
class FlightInputs {
 public:
  virtual ~FlightInputs() = default;
  /// The position-level reference at simulated time t, dt after the previous call.
  virtual Setpoint reference(double t, double dt) = 0;
  /// Whether the reference's yaw is to be held (external set-points, trajectories), not only its
  /// yaw rate followed.
  virtual bool holdsHeading() const = 0;
  /// The vehicle's pose and velocity from its position source (motion capture, else the truth).
  virtual void position(Pose& pose, Vec3& velocity) const = 0;
  /// The body's angular velocity in its own frame, rad/s (the truth: a controller that models its
  /// gyroscope reads the IMU instead, as TeleKybController does).
  virtual Vec3 bodyRates() const = 0;
  /// When the position source's latest sample was taken (ns); -1 for the truth, new at every run.
  virtual Nanoseconds positionStamp() const { return -1; }
  /// The IMU's latest sample, for a controller that estimates its state from it (nullptr: none).
  virtual const ImuMeasurement* imu() const { return nullptr; }
};

class FlightController {
 public:
  virtual ~FlightController() = default;
  virtual bool accepts(CommandLevel level) const = 0;
  /// The level of the latest command.
  virtual CommandLevel level() const = 0;
  /// Takes a command (checked by the caller: CommandInterface::refusal). A position command
  /// only switches the level: its set-point is the references' (FlightInputs::reference).
  /// `position`: the vehicle's, now.
  virtual void setCommand(const Command& command, const Vec3& position) = 0;
  /// The set-point tracked at the position and velocity levels.
  virtual Setpoint currentSetpoint() const = 0;
  /// The command followed now (CommandInterface::currentCommand); this default knows the level and,
  /// at the position level, the set-point.
  virtual Command command() const {
    Command c;
    c.level = level();
    if (c.level == CommandLevel::Position) c.setpoint = currentSetpoint();
    return c;
  }
  /// Before the first step: the vehicle starts in the air carrying `weight` N (0: on the ground);
  /// a controller with integrators may start them there.
  virtual void startInAir(double /*weight*/) {}
  /// The battery's terminal voltage, when the vehicle has a battery: at load (`initial`: the
  /// voltage since it was switched on) and before each run. A controller that compensates the
  /// battery (the Crazyflie's firmware) reads it; the others need not.
  virtual void batteryVoltage(double /*volts*/, bool /*initial*/) {}
  /// One run of the driver (`run` counts them from 0, at simulated time `t`): writes the commanded
  /// speed of each rotor (rad/s) into `speeds`, or leaves them as they were.
  virtual void step(std::int64_t run, double t, FlightInputs& in, std::span<double> speeds) = 0;
  virtual void saveState(StateWriter& out) const = 0;
  virtual void loadState(StateReader& in) = 0;
};

}  // namespace ssx::quadrotor
