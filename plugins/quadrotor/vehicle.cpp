#include "vehicle.hpp"

#include <algorithm>
#include <sstream>
#include <string>

namespace ssx::quadrotor {

namespace {

std::vector<std::string> words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// a value the parameters give (the element's, else its preset's), else the model's default
void presetOr(const Descriptor& params, const char* key, double& value) { value = params.get<double>(key, value); }

// the rotor and motor constants (values checked while loading)
RotorParams rotorParams(const Descriptor& params) {
  RotorParams rp;
  presetOr(params, "thrust_coefficient", rp.thrust_coefficient);
  presetOr(params, "moment_constant", rp.moment_constant);
  presetOr(params, "time_constant_up", rp.time_constant_up);
  presetOr(params, "time_constant_down", rp.time_constant_down);
  presetOr(params, "max_rotor_speed", rp.max_rotor_speed);
  presetOr(params, "min_rotor_speed", rp.min_rotor_speed);
  presetOr(params, "rotor_drag_coefficient", rp.rotor_drag_coefficient);
  presetOr(params, "rolling_moment_coefficient", rp.rolling_moment_coefficient);
  presetOr(params, "rotor_inertia", rp.rotor_inertia);
  presetOr(params, "rotor_radius", rp.rotor_radius);
  if (rp.min_rotor_speed >= rp.max_rotor_speed) {
    std::ostringstream m;
    m << "min_rotor_speed (" << rp.min_rotor_speed << " rad/s) must be below max_rotor_speed (" << rp.max_rotor_speed
      << " rad/s)";
    throw params.error(m.str());
  }
  return rp;
}

// the battery; its voltages checked against each other
BatteryParams batteryParams(const Descriptor& params) {
  BatteryParams bp;
  presetOr(params, "battery_full_voltage", bp.full_voltage);
  presetOr(params, "battery_empty_voltage", bp.empty_voltage);
  presetOr(params, "battery_capacity", bp.capacity);
  presetOr(params, "battery_resistance", bp.resistance);
  presetOr(params, "battery_efficiency", bp.efficiency);
  presetOr(params, "battery_initial_charge", bp.initial_charge);
  presetOr(params, "battery_nominal_voltage", bp.nominal_voltage);
  presetOr(params, "battery_zero_thrust_voltage", bp.zero_thrust_voltage);
  bp.compensated = params.get<bool>("battery_compensated");
  if (!(bp.empty_voltage < bp.full_voltage) || !(bp.nominal_voltage > bp.zero_thrust_voltage) ||
      !(bp.empty_voltage > bp.zero_thrust_voltage))
    throw params.error("battery: needs battery_zero_thrust_voltage < battery_empty_voltage < battery_full_voltage "
                       "and battery_nominal_voltage > battery_zero_thrust_voltage");
  return bp;
}

}  // namespace

VehicleParams::VehicleParams(const Descriptor& params) : rotor(rotorParams(params)) {
  rotor_names = words(params.get<std::string>("rotors"));
  const auto& names = rotor_names;
  const auto dirs = words(params.get<std::string>("directions"));
  if (names.size() != dirs.size() || names.size() < 4 || names.size() > kMaxRotors)
    throw params.errorAt(names.size() != dirs.size() ? "directions" : "rotors",
                         "'rotors' and 'directions' must name the same number (4 to " + std::to_string(kMaxRotors) +
                             ") of rotors");
  // one rotor named twice would be pushed twice and leave another out
  for (std::size_t i = 0; i < names.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (names[i] == names[j])
        throw params.errorAt("rotors", "rotor '" + names[i] + "' is named twice: name each rotor node once");
  for (const auto& d : dirs) {
    if (d != "1" && d != "-1") throw params.errorAt("directions", "rotor directions are 1 or -1, got '" + d + "'");
    directions.push_back(d == "1" ? 1 : -1);
  }
  if (params.get<bool>("battery")) battery = batteryParams(params);
  const auto factors = words(params.get<std::string>("rotor_thrust_factors", ""));
  if (!factors.empty() && factors.size() != names.size())
    throw params.errorAt("rotor_thrust_factors", "give one factor per rotor (" + std::to_string(names.size()) +
                                                     "), got " + std::to_string(factors.size()));
  for (const auto& f : factors) {
    std::size_t used = 0;
    double value = 0;
    try {
      value = std::stod(f, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != f.size() || !(value >= 0.5 && value <= 1.5))
      throw params.errorAt("rotor_thrust_factors", "'" + f + "' is not a factor from 0.5 to 1.5");
    thrust_factors.push_back(value);
  }
}

std::vector<Rotor> VehicleParams::rotorsOf(const Descriptor& params, const Artifact& a) const {
  std::vector<Rotor> rotors;
  for (std::size_t i = 0; i < rotor_names.size(); ++i) {
    const PhysicNode* node = a.node(rotor_names[i]);
    if (node == nullptr)
      throw params.errorAt("rotors",
                           "no physic node '" + rotor_names[i] + "' for a rotor in artifact '" + a.name() + "'");
    // a rotor on a joint of its own (a propeller link of a URDF or SDF robot) counts where it sits
    // on the frame, its joints at 0: the thrust acts on the frame
    Pose in_root;
    bool joined = false;
    for (const PhysicNode* n = node; n != nullptr && n != &a.root(); n = n->parent()) {
      in_root = n->spec().pose * in_root;
      joined = joined || n->spec().joint.isBody();
    }
    rotors.push_back({joined ? (a.root().poseInBody() * in_root).position : node->poseInBody().position, directions[i]});
  }
  return rotors;
}

void Vehicle::configure(const RotorModel& at_rest, const Vec3& com_in_root, const std::optional<BatteryParams>& battery,
                        const std::vector<double>& thrust_factors) {
  rotors_.emplace(at_rest);
  com_in_root_ = com_in_root;
  factors_.fill(1.0);
  std::copy(thrust_factors.begin(), thrust_factors.end(), factors_.begin());
  gains_ = factors_;
  if (!thrust_factors.empty()) rotors_->setThrustGains(std::span(gains_).first(rotors_->size()));
  battery_.reset();
  if (battery) battery_.emplace(*battery);
}

void Vehicle::saveState(StateWriter& out) const {
  // (per-rotor arrays as vectors of the rotor count)
  const std::size_t n = rotors_->size();
  out.write(std::vector<double>(rotors_->speeds().begin(), rotors_->speeds().end()));
  out.write(std::vector<double>(gains_.begin(), gains_.begin() + static_cast<std::ptrdiff_t>(n)));
  out.write(battery_ ? battery_->charge() : 0.0);
  out.write(battery_ ? battery_->voltage() : 0.0);
}

void Vehicle::loadState(StateReader& in) {
  std::vector<double> speeds, gains;
  in.read(speeds);
  if (speeds.size() != rotors_->size())
    throw StateError("quadrotor: saved with " + std::to_string(speeds.size()) + " rotors, this one has " +
                     std::to_string(rotors_->size()));
  in.read(gains);
  if (gains.size() != speeds.size()) throw StateError("quadrotor: the saved thrust gains do not fit this vehicle");
  rotors_->setSpeeds(speeds);
  std::copy(gains.begin(), gains.end(), gains_.begin());
  rotors_->setThrustGains(gains);
  const double charge = in.get<double>(), voltage = in.get<double>();
  if (battery_) battery_->setState(charge, voltage);
}

}  // namespace ssx::quadrotor
