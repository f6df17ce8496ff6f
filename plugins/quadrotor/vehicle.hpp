#pragma once
// The vehicle: a rigid body and its rotors (first-order motors, thrust and reaction torque, rotor
// drag and rolling moment, gyroscopic torque) and an optional battery whose voltage the thrust
// follows. It turns commanded rotor speeds into a wrench on the body; it knows nothing of how the
// speeds were chosen (controller.hpp) or of the air around it (effects.hpp).
// Parameters: kVehicleParameters.
#include "quadrotor_model.hpp"

#include <ssx/ssx.hpp>

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace ssx::quadrotor {

// `preset`: the quadrotor's presets (libssx's presets: a text parameter named `preset` whose
// `choices` name the family, here for every class that flies this vehicle)
inline constexpr ssx_plugin_param kPresetParameter = [] {
  ssx_plugin_param p = param::text("preset", "mk_quad",
                                   "the values to start from, for every parameter not given: a preset's name "
                                   "(presets/quadrotor/NAME.xml in the artifact path or installed: mk_quad, "
                                   "hummingbird, crazyflie) or a preset file's path");
  p.choices = "quadrotor";
  return p;
}();

inline constexpr ssx_plugin_param kVehicleParameters[] = {
    kPresetParameter,
    param::real("thrust_coefficient", "", "N s^2", param::positive(),
                "thrust per squared rotor speed (default: the preset's)"),
    param::real("moment_constant", "", "m", param::positive(), "drag torque per thrust (default: the preset's)"),
    param::real("time_constant_up", "", "s", param::positive(),
                "motor time constant, speeding up (default: the preset's)"),
    param::real("time_constant_down", "", "s", param::positive(),
                "motor time constant, slowing down (default: the preset's)"),
    param::real("max_rotor_speed", "", "rad/s", param::positive(), "(default: the preset's)"),
    param::real("min_rotor_speed", "", "rad/s", param::nonNegative(), "below max_rotor_speed (default: the preset's)"),
    param::real("rotor_drag_coefficient", "", "N s/m", param::nonNegative(), "rotor drag (default: the preset's)"),
    param::real("rolling_moment_coefficient", "", "N m s/m", param::nonNegative(),
                "rolling moment (default: the preset's)"),
    param::real("rotor_radius", "", "m", param::positive(),
                "propeller radius, for ground effect (default: the preset's)"),
    param::real("rotor_inertia", "", "kg m^2", param::nonNegative(), "(default: the preset's)"),
    param::text("rotors", "rotor0 rotor1 rotor2 rotor3", "physic node names of the rotors (4 to 8)"),
    param::text("directions", "1 -1 1 -1", "spin of each rotor: 1 counter-clockwise seen from above, -1 clockwise"),
    param::text("rotor_thrust_factors", "",
                "each rotor's thrust relative to the model's, one factor (0.5-1.5) per rotor in the order of 'rotors' "
                "(worn or other propellers, a weak motor; the flight controller is not told; default: all 1)"),
    param::flag("battery", "false",
                "a battery whose voltage sags with current and charge drawn; thrust at a fixed command follows it "
                "(the crazyflie's firmware compensates: its thrust holds until the voltage cannot give it)"),
    param::real("battery_full_voltage", "", "V", param::positive(),
                "open circuit when full (default: the preset's; mk_quad 16.8)"),
    param::real("battery_empty_voltage", "", "V", param::positive(),
                "open circuit when the capacity is drawn (default: the preset's; mk_quad 14, EST)"),
    param::real("battery_capacity", "", "Ah", param::positive(), "capacity (default: the preset's; mk_quad 2.2, EST)"),
    param::real("battery_resistance", "", "ohm", param::nonNegative(),
                "internal resistance (default: the preset's; mk_quad 0.04, EST)"),
    param::real("battery_efficiency", "", "", param::positive() & param::atMost(1),
                "mechanical / electrical power (default: the preset's; mk_quad 0.6, EST)"),
    param::flag(
        "battery_compensated", "false",
        "the flight controller reads the voltage and compensates: no thrust law here (the crazyflie's firmware; "
        "needs controller=\"crazyflie_pid\")"),
    param::real("battery_initial_charge", "1", "", param::nonNegative() & param::atMost(1),
                "fraction of the capacity at the start"),
    param::real("battery_nominal_voltage", "", "V", param::positive(),
                "voltage at which the rotor model's thrust holds (MK law; default: the preset's; mk_quad 15.5)"),
    param::real("battery_zero_thrust_voltage", "", "V", param::nonNegative(),
                "the MK law's offset: thrust at a fixed command is proportional to U minus this (default: the "
                "preset's; mk_quad 7.575)"),
};

/// The vehicle's constants from its parameters, checked against each other.
struct VehicleParams {
  RotorParams rotor;
  std::vector<std::string> rotor_names;
  std::vector<int> directions;  // 1 or -1 per rotor
  std::optional<BatteryParams> battery;
  std::vector<double> thrust_factors;  // one per rotor (1: as the model)
  explicit VehicleParams(const Descriptor& params);
  /// The rotors at artifact `a`'s physic nodes, positions relative to the centre of mass.
  std::vector<Rotor> rotorsOf(const Descriptor& params, const Artifact& a) const;
};

class Vehicle {
 public:
  /// `at_rest`: the rotors (copied; copies share their constants); `com_in_root`: where the
  /// centre of mass is in the root body's frame.
  /// `thrust_factors`: one per rotor (empty: all 1), on each rotor's thrust from now on.
  void configure(const RotorModel& at_rest, const Vec3& com_in_root, const std::optional<BatteryParams>& battery,
                 const std::vector<double>& thrust_factors = {});
  const RotorModel& rotors() const { return *rotors_; }
  std::size_t rotorCount() const { return rotors_->size(); }
  /// Its rotors' constants from now on (RotorModel::setParams).
  void setRotorParams(const RotorParams& params, const RotorModel& nominal) { rotors_->setParams(params, nominal); }
  /// Sets every rotor spinning at `speed` (a vehicle placed in the air starts at its hover speed).
  void spinAt(std::span<const double> speeds) { rotors_->setSpeeds(speeds); }
  /// Advances the motors by dt towards the commanded speeds (one per rotor).
  void stepMotors(double dt, std::span<const double> commanded) { rotors_->step(dt, commanded); }
  /// Whether thrust gains change from step to step (a battery; or ground effect, told by the caller).
  bool hasBattery() const { return battery_.has_value(); }
  /// Volts added to the battery's open-circuit voltage from the next step on (Battery::setOffset).
  void setBatteryOffset(double volts) {
    if (battery_) battery_->setOffset(volts);
  }
  /// The battery's terminal voltage (V) after the last step; call only with a battery.
  double batteryVoltage() const { return battery_->voltage(); }
  /// Updates each rotor's thrust gain: the battery's (after drawing the rotors' power for dt) times
  /// `ground_gain(i)`, a per-rotor gain from the environment (1: none).
  template <class GroundGain>
  void updateGains(double dt, GroundGain ground_gain);
  /// The rotors' wrench on the body for its state `s` (root) and `com` (centre of mass) in air
  /// moving at `air` (world frame).
  void applyWrench(PhysicNode& body, const BodyState& s, const BodyState& com, const Vec3& air) const {
    // motors and aerodynamics, applied at the centre of mass in body axes
    const Quat to_body = s.pose.orientation.conjugate();
    const Vec3 v_air = com.linear_velocity - air;
    Vec3 force, torque;
    rotors_->wrench(to_body * v_air, to_body * s.angular_velocity, force, torque);
    body.addForce(force, Frame::Local, com_in_root_, Frame::Local);
    body.addTorque(torque, Frame::Local);
  }
  /// Adds a world-frame force at the centre of mass.
  void push(PhysicNode& body, const Vec3& force) const {
    body.addForce(force, Frame::World, com_in_root_, Frame::Local);
  }

  void saveState(StateWriter& out) const;
  void loadState(StateReader& in);

 private:
  std::optional<RotorModel> rotors_;
  Vec3 com_in_root_ = Vec3::Zero();
  std::optional<Battery> battery_;
  std::array<double, kMaxRotors> gains_{};    // per rotor thrust gains, handed to the rotor model
  std::array<double, kMaxRotors> factors_{};  // per rotor thrust factors (rotor_thrust_factors)
};

template <class GroundGain>
void Vehicle::updateGains(double dt, GroundGain ground_gain) {
  const auto& rotors = rotors_->rotors();
  const RotorParams& rp = rotors_->params();
  double battery_gain = 1.0;
  if (battery_) {
    // the power the rotors take at the last gains: torque times speed
    double power = 0;
    for (std::size_t i = 0; i < rotors.size(); ++i) {
      const double w = std::abs(rotors_->speeds()[i]);
      power += rp.moment_constant * rp.thrust_coefficient * w * w * gains_[i] * w;
    }
    battery_->step(dt, power);
    battery_gain = battery_->thrustGain();
  }
  for (std::size_t i = 0; i < rotors.size(); ++i) gains_[i] = battery_gain * ground_gain(i) * factors_[i];
  rotors_->setThrustGains(std::span(gains_).first(rotors.size()));
}

}  // namespace ssx::quadrotor
