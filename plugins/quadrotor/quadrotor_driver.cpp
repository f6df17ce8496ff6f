#include "quadrotor_driver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ssx::quadrotor {

// Every part's parameters but the member's own formation_index, parsed and checked against
// themselves once per parameter set: a swarm's members share one.
struct QuadrotorDriver::Config {
  VehicleParams vehicle;
  bool ground_effect;
  WindParams wind;
  bool downwash;
  DownwashParams downwash_params;
  TeleKybParams controller;
  ReferenceParams reference;
  bool crazyflie_pid;
  CrazyfliePidGains crazyflie_gains;
  double crazyflie_battery;

  Config(const Descriptor& params, const Environment& env)
      : vehicle(params),
        ground_effect(params.get<bool>("ground_effect")),
        wind(windParams(params, env.settings().wind)),
        downwash(params.get<bool>("downwash")),
        downwash_params(DownwashParams::of(params)),
        controller(params),
        reference(params),
        crazyflie_pid(params.get<std::string>("controller") == "crazyflie_pid"),
        crazyflie_battery(params.get<double>("crazyflie_battery_volts")) {
    crazyflie_gains.position_rate_hz = params.get<double>("crazyflie_position_rate_hz");
    crazyflie_gains.attitude_rate_hz = params.get<double>("crazyflie_attitude_rate_hz");
    crazyflie_gains.kalman = params.get<std::string>("crazyflie_estimator") == "kalman";
  }
  // the Crazyflie's controller for these rotors, run by a driver of this context (invalid_argument
  // for another frame than an X of four, or rates that do not fit)
  std::unique_ptr<CrazyfliePidController> crazyflie(const std::vector<Rotor>& rotors, const PluginContext& context) const {
    auto c = std::make_unique<CrazyfliePidController>(crazyflie_gains, rotors, vehicle.rotor);
    c->setRuns(runsPerPeriod(crazyflie_gains.attitude_rate_hz, context),
               runsPerPeriod(crazyflie_gains.position_rate_hz, context), toSeconds(context.period()));
    c->setBatteryVoltage(crazyflie_battery);
    return c;
  }
  // the text a Config is parsed from (every given parameter but formation_index); marks those read
  static std::string key(const Descriptor& params) {
    std::string key;
    for (const auto& a : params.attributes()) {
      if (a.key == "formation_index") continue;
      // the constructor reads every declared parameter, this member's as well as the first's
      if (std::any_of(std::begin(kParameters), std::end(kParameters),
                      [&](const ssx_plugin_param& d) { return a.key == d.name; }))
        a.used = true;
      // lengths first: no value can run into the next
      key += std::to_string(a.key.size()) + ":" + a.key + std::to_string(a.value.size()) + ":" + a.value;
    }
    return key;
  }
};

// What the rotors' places make of a Config: shared by the members of one artifact type.
struct QuadrotorDriver::Airframe {
  std::vector<Rotor> rotors;
  RotorModel rotor_model;  // at rest; each driver copies it (the copies share its constants)
  TeleKybAirframe controller;

  // the airframe of artifact `a`, checked against what the integer inner loop can hold
  Airframe(const Config& c, const Descriptor& params, const Artifact& a)
      : rotors(c.vehicle.rotorsOf(params, a)), rotor_model(rotors, c.vehicle.rotor) {
    const MassProperties mass = combinedMass(a.root().spec());
    controller.mass = mass.mass;
    controller.inertia = c.controller.controller_inertia ? Mat3(c.controller.controller_inertia->asDiagonal())
                                                         : mass.inertia;
    const Allocation allocation(rotors, c.vehicle.rotor);
    Eigen::Matrix4d scale = Eigen::Matrix4d::Identity();
    scale.topLeftCorner<3, 3>() = controller.inertia;
    controller.mixer = allocation.inverse() * scale;
    const double w_max = c.vehicle.rotor.max_rotor_speed;
    controller.rotor_max_thrust = allocation.matrix().row(3).sum() * w_max * w_max;
    // a thrust the rotors cannot give would be commanded and never reached (it saturated silently)
    if (c.controller.max_thrust && *c.controller.max_thrust > controller.rotor_max_thrust)
      throw params.errorAt("max_thrust", "max_thrust " + std::to_string(*c.controller.max_thrust) +
                                             " N is more than these rotors give at full speed (" +
                                             std::to_string(controller.rotor_max_thrust) + " N)");
    if (!mixerFitsFixedPoint(controller.mixer, c.controller.max_angular_acceleration, controller.rotor_max_thrust))
      // at the value that was given, if one was
      throw params.errorAt(params.has("max_angular_acceleration") || !params.has("controller_inertia")
                               ? "max_angular_acceleration"
                               : "controller_inertia",
                           "the integer attitude loop cannot hold the mixer of these rotors and this inertia in 64 "
                           "bits at this max_angular_acceleration: lower it, or check the rotors' positions");
  }
};

namespace {

template <class M>
const Sensor* firstSensorOf(const Artifact& a) {
  for (std::size_t i = 0; i < a.sensorCount(); ++i)
    if (dynamic_cast<const M*>(&a.sensor(i).latest()) != nullptr) return &a.sensor(i);
  return nullptr;
}

std::string frameKey(const void* config, const Artifact& a) {
  std::ostringstream key;
  key << config << ' ' << &a.root().spec();
  return key.str();
}

}  // namespace

void QuadrotorDriver::validate(const Descriptor& params, const PluginContext& context) {
  const Artifact& a = *context.artifact;
  if (a.rootCount() == 0 || a.root().isStatic()) throw params.error("a quadrotor needs a dynamic physic root");
  // parsed and checked once per parameter set and artifact type (a swarm's members share them)
  const auto shared_config =
      context.shared<Config>(Config::key(params), [&] { return Config(params, *context.environment); });
  const Config& config = *shared_config;
  const auto frame =
      context.shared<Airframe>(frameKey(shared_config.get(), a), [&] { return Airframe(config, params, a); });
  if (config.vehicle.battery && config.vehicle.battery->compensated && !config.crazyflie_pid)
    throw params.errorAt("battery", "this battery is compensated by the flight controller (battery_compensated, the "
                                    "crazyflie's firmware): fly "
                                    "controller=\"crazyflie_pid\" with battery=\"true\"");
  if (config.crazyflie_gains.kalman && !config.crazyflie_pid)
    throw params.errorAt("crazyflie_estimator",
                         "crazyflie_estimator=\"kalman\" is the Crazyflie firmware's filter: fly "
                         "controller=\"crazyflie_pid\" with it (TeleKyb's controller has none)");
  if (config.crazyflie_pid) {
    // (checked only for this controller: the rates mean nothing to TeleKyb's)
    const double period = toSeconds(context.period());
    for (const char* rate : {"crazyflie_attitude_rate_hz", "crazyflie_position_rate_hz"}) {
      const double runs = 1.0 / (params.get<double>(rate) * period);
      if (runs < 1 - 1e-9 || std::abs(runs - std::round(runs)) > 1e-6)
        throw params.errorAt(rate, std::string(rate) + ": its period must be a whole multiple of the driver's (" +
                                       std::to_string(period * 1e3) + " ms)");
    }
    try {
      (void)config.crazyflie(frame->rotors, context);
    } catch (const std::invalid_argument& e) {
      throw params.errorAt("controller", std::string(e.what()) + " (the rotors: the `rotors` parameter)");
    }
  }
  // checked while loading, so that `ssx validate` refuses what `ssx run` would
  (void)config.controller.commandDelayTicks(params, context);
  if (firstSensorOf<ImuMeasurement>(a) == nullptr)
    throw params.error("a quadrotor needs an IMU: add <sensor plugin=\"imu\"/> to the artifact");
  if (config.reference.reference == "formation") {
    const auto index = params.get<std::int64_t>("formation_index");
    if (static_cast<std::size_t>(index) >= config.reference.formation_size ||
        static_cast<std::size_t>(index) > a.index())
      throw params.errorAt("formation_index",
                           "formation_index must be below formation_size and the members one swarm");
    if (firstSensorOf<RangeMeasurement>(a) == nullptr)
      throw params.error("reference=\"formation\" needs a range sensor on the artifact");
  }
  if (config.reference.reference == "follow") {
    const Artifact* followed = context.environment->findArtifact(config.reference.follow);
    if (followed == nullptr || followed->rootCount() == 0 || followed == &a)
      throw params.errorAt("follow", "no other artifact with a physic root is named '" + config.reference.follow + "'");
  }
}

void QuadrotorDriver::configure(const Descriptor& params, PluginSetup& setup) {
  Artifact& a = artifact();
  const Environment& env = environment();
  // parsed once per parameter set, and worked out once per parameter set and artifact type
  const auto config = setup.shared<Config>(Config::key(params), [&] { return Config(params, env); });
  const Config& c = *config;
  const std::string frame_key = frameKey(config.get(), a);
  const auto frame = setup.shared<Airframe>(frame_key, [&] { return Airframe(c, params, a); });

  // the vehicle
  vehicle_.configure(frame->rotor_model, -a.root().poseInBody().position, c.vehicle.battery, c.vehicle.thrust_factors);
  frame_ = frame;
  rotor_factors_.fill(1.0);
  wind_offset_.setZero();
  // the effects: ground effect over the highest horizontal ground plane, if there is one; the air
  ground_z_ = groundHeight(env);
  ground_effect_ = c.ground_effect;
  wind_.configure(c.wind, ground_z_);
  downwash_.reset();
  if (c.downwash) {
    downwash_.emplace(c.downwash_params);
    setup.enableNeighborQueries(c.downwash_params.range);
  }

  // the controller reads the IMU (required); a pose source (optional) stands in for motion capture
  const Sensor* imu = firstSensorOf<ImuMeasurement>(a);
  if (imu == nullptr) throw params.error("a quadrotor needs an IMU: add <sensor plugin=\"imu\"/> to the artifact");
  const PluginContext context{&env, &a, periodSteps(), env.timestep(), {}};
  imu_ = nullptr;
  if (c.crazyflie_pid) {
    flight_ = c.crazyflie(frame->rotors, context);
    // its estimator reads the IMU's latest sample in place
    if (c.crazyflie_gains.kalman) imu_ = static_cast<const ImuMeasurement*>(&imu->latest());
  } else {
    // (the one asked before the start, holding any command given then)
    if (dynamic_cast<TeleKybController*>(flight_.get()) == nullptr) flight_ = std::make_unique<TeleKybController>();
    static_cast<TeleKybController&>(*flight_).configure(c.controller, frame->controller, c.vehicle.rotor, params,
                                                        context, *imu, setup, frame_key);
  }
  // (a firmware has measured the battery since it was switched on)
  if (vehicle_.hasBattery()) flight_->batteryVoltage(vehicle_.batteryVoltage(), true);
  battery_varies_ = vehicle_.hasBattery() || c.crazyflie_pid;
  crazyflie_battery_ = c.crazyflie_battery;
  if (const Sensor* pose = firstSensorOf<PoseMeasurement>(a)) {
    have_pose_ = true;
    setup.subscribe<PoseMeasurement>(*pose, [this](const PoseMeasurement& m) { pose_ = m; });
  }

  // the references (the formation reads the range sensor's measurement in place)
  const Sensor* range = firstSensorOf<RangeMeasurement>(a);
  references_.configure(c.reference, params, a,
                        range != nullptr ? static_cast<const RangeMeasurement*>(&range->latest()) : nullptr);
  hold_.configure(params, a);

  // a vehicle placed in the air starts with its rotors at hover speed
  commanded_speeds_.fill(0.0);
  const std::size_t n = frame->rotors.size();
  if (a.placement().position.z() > 0.1) {
    const double g = -env.settings().physics.gravity.z();
    const double hover = std::sqrt(frame->controller.mass * g / (static_cast<double>(n) * c.vehicle.rotor.thrust_coefficient));
    commanded_speeds_.fill(hover);
    vehicle_.spinAt(std::span(commanded_speeds_).first(n));
    flight_->startInAir(frame->controller.mass * g);
  } else {
    flight_->startInAir(0);
  }
}

void QuadrotorDriver::setCommand(const Command& command) {
  if (const std::string why = refusal(command); !why.empty()) throw std::invalid_argument("quadrotor: " + why);
  if (command.level == CommandLevel::Position) references_.setExternal(command.setpoint);
  flight_->setCommand(command, artifact().state().pose.position);
}

Command QuadrotorDriver::currentCommand() const {
  Command c = flight().command();
  if (c.level == CommandLevel::Rotors) c.rotor_speeds.resize(vehicle_.rotorCount());
  return c;
}

void QuadrotorDriver::position(Pose& pose, Vec3& velocity) const {
  if (have_pose_) {
    pose = pose_.pose;
    velocity = pose_.linear_velocity;
    return;
  }
  const BodyState truth = artifact().state();
  pose = truth.pose;
  velocity = truth.linear_velocity;
}

void QuadrotorDriver::step(const StepInfo& info) {
  hold_.step(info);
  const double period = info.periodSeconds();
  const double t = toSeconds(info.time);
  const std::size_t n = vehicle_.rotorCount();
  // the controller chooses the rotor speeds, the vehicle spins up to them
  if (vehicle_.hasBattery()) flight_->batteryVoltage(vehicle_.batteryVoltage(), false);
  flight_->step(info.step / periodSteps(), t, *this, std::span(commanded_speeds_).first(n));
  if (references_.source() == References::Source::Follow) {
    // down on the robot it follows: the motors stop for good (it rides on the deck)
    Pose at;
    Vec3 velocity;
    position(at, velocity);
    landed_ = landed_ || references_.touchedDown(at.position, t);
    if (landed_) std::fill(commanded_speeds_.begin(), commanded_speeds_.begin() + static_cast<std::ptrdiff_t>(n), 0.0);
  }
  vehicle_.stepMotors(period, std::span(commanded_speeds_).first(n));
  PhysicNode& body = artifact().root();
  const BodyState s = body.state();
  const BodyState& com = artifact().environment().bodyState(body.bodyIndex());
  // the body moves relative to the air: mean wind, the gust, the turbulence
  const Vec3 air = wind_.active() ? wind_.air(t, period, com.pose.position, com.linear_velocity, random()) : Vec3::Zero();
  // robots above push this one down
  if (downwash_) {
    const double push =
        downwash_->push(environment(), artifact().index(), artifact().pose().position, vehicle_.rotors().params().rotor_radius);
    if (push != 0) vehicle_.push(body, Vec3(0, 0, push));
  }
  if (ground_effect_ || vehicle_.hasBattery()) {
    const auto& rotors = vehicle_.rotors().rotors();
    const double radius = vehicle_.rotors().params().rotor_radius;
    vehicle_.updateGains(period, [&](std::size_t i) {
      return ground_effect_ ? groundEffectGain(com.pose.transformPoint(rotors[i].position).z() - ground_z_, radius) : 1.0;
    });
  }
  vehicle_.applyWrench(body, s, com, air);
}

std::vector<std::string> QuadrotorDriver::metricNames() const {
  if (references_.source() == References::Source::Formation) return {"formation_error"};
  if (references_.source() == References::Source::Follow) return {"landed"};
  return {};
}

void QuadrotorDriver::metrics(std::vector<Metric>& out) const {
  if (references_.source() == References::Source::Follow) out.push_back({"landed", landed_ ? 1.0 : 0.0});
  if (references_.source() != References::Source::Formation) return;
  out.push_back({"formation_error", references_.formationError()});
}

// what changes while it flies: each part's state, what the driver last commanded and received
namespace {

constexpr Variable kVariables[] = {
    {"thrust_coefficient", 1.0, 0.2, 5.0, "factor on the rotors' thrust coefficient"},
    {"moment_constant", 1.0, 0.2, 5.0, "factor on the rotors' drag torque per thrust"},
    {"time_constant_up", 1.0, 0.1, 10.0, "factor on the motors' time constant speeding up"},
    {"time_constant_down", 1.0, 0.1, 10.0, "factor on the motors' time constant slowing down"},
    {"wind_x", 0.0, -50.0, 50.0, "m/s added to the mean wind along x (world frame)"},
    {"wind_y", 0.0, -50.0, 50.0, "m/s added to the mean wind along y (world frame)"},
    {"wind_z", 0.0, -50.0, 50.0, "m/s added to the mean wind along z (world frame)"},
    // (listed only for a vehicle with a battery: a battery model, or the Crazyflie's controller)
    {"battery_volts", 0.0, -2.0, 0.5,
     "V added to the battery's voltage (the Crazyflie's crazyflie_battery_volts, or a battery model's open circuit)"},
};
constexpr std::size_t kBatteryVariable = 7;

}  // namespace

std::span<const Variable> QuadrotorDriver::variables() const {
  return std::span(kVariables).first(battery_varies_ ? kBatteryVariable + 1 : kBatteryVariable);
}

void QuadrotorDriver::vary(std::size_t k, double value) {
  if (k == kBatteryVariable) {
    // a battery model's open circuit moves; the Crazyflie's held battery is measured anew (its
    // firmware has measured it since it was switched on)
    if (vehicle_.hasBattery()) {
      vehicle_.setBatteryOffset(value);
    } else if (auto* cf = dynamic_cast<CrazyfliePidController*>(flight_.get())) {
      cf->setBatteryVoltage(crazyflie_battery_ + value);
    }
    return;
  }
  if (k >= 4) {
    wind_offset_[static_cast<Eigen::Index>(k - 4)] = value;
    wind_.setOffset(wind_offset_);
    return;
  }
  rotor_factors_[k] = value;
  RotorParams p = frame_->rotor_model.params();
  p.thrust_coefficient *= rotor_factors_[0];
  p.moment_constant *= rotor_factors_[1];
  p.time_constant_up *= rotor_factors_[2];
  p.time_constant_down *= rotor_factors_[3];
  vehicle_.setRotorParams(p, frame_->rotor_model);
}

void QuadrotorDriver::saveState(StateWriter& out) const {
  vehicle_.saveState(out);
  out.write(std::vector<double>(commanded_speeds_.begin(),
                                commanded_speeds_.begin() + static_cast<std::ptrdiff_t>(vehicle_.rotorCount())));
  flight_->saveState(out);
  references_.saveState(out);
  wind_.saveState(out);
  ssx::save(out, pose_);
  out.write(landed_);
}

void QuadrotorDriver::loadState(StateReader& in) {
  vehicle_.loadState(in);
  std::vector<double> commanded;
  in.read(commanded);
  if (commanded.size() != vehicle_.rotorCount())
    throw StateError("quadrotor: the saved commanded speeds do not fit this driver");
  std::copy(commanded.begin(), commanded.end(), commanded_speeds_.begin());
  flight_->loadState(in);
  references_.loadState(in);
  wind_.loadState(in);
  ssx::load(in, pose_);
  in.read(landed_);
}

}  // namespace ssx::quadrotor
