#include "quadrotor_driver.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace ssx::quadrotor {

namespace {

// room for the neighbours a formation robot senses at once, reserved at start
constexpr std::size_t kTypicalNeighbours = 16;
// m per axis: how far the velocity level's reference point may lead the vehicle
constexpr double kVelocityLeash = 0.3;

std::vector<std::string> words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// the rotor and motor constants: the preset, then any override (values checked while loading)
RotorParams rotorParams(const Descriptor& params) {
  RotorParams rp = *preset(params.get<std::string>("preset"));
  auto override = [&](const char* key, double& value) { value = params.get<double>(key, value); };
  override("thrust_coefficient", rp.thrust_coefficient);
  override("moment_constant", rp.moment_constant);
  override("time_constant_up", rp.time_constant_up);
  override("time_constant_down", rp.time_constant_down);
  override("max_rotor_speed", rp.max_rotor_speed);
  override("min_rotor_speed", rp.min_rotor_speed);
  override("rotor_drag_coefficient", rp.rotor_drag_coefficient);
  override("rolling_moment_coefficient", rp.rolling_moment_coefficient);
  override("rotor_inertia", rp.rotor_inertia);
  override("rotor_radius", rp.rotor_radius);
  if (rp.min_rotor_speed >= rp.max_rotor_speed) {
    std::ostringstream m;
    m << "min_rotor_speed (" << rp.min_rotor_speed << " rad/s) must be below max_rotor_speed (" << rp.max_rotor_speed
      << " rad/s)";
    throw params.error(m.str());
  }
  return rp;
}

// the battery, its voltages checked against each other
BatteryParams batteryParams(const Descriptor& params) {
  BatteryParams bp;
  bp.full_voltage = params.get<double>("battery_full_voltage");
  bp.empty_voltage = params.get<double>("battery_empty_voltage");
  bp.capacity = params.get<double>("battery_capacity");
  bp.resistance = params.get<double>("battery_resistance");
  bp.efficiency = params.get<double>("battery_efficiency");
  bp.initial_charge = params.get<double>("battery_initial_charge");
  bp.nominal_voltage = params.get<double>("battery_nominal_voltage");
  bp.zero_thrust_voltage = params.get<double>("battery_zero_thrust_voltage");
  if (!(bp.empty_voltage < bp.full_voltage) || !(bp.nominal_voltage > bp.zero_thrust_voltage) ||
      !(bp.empty_voltage > bp.zero_thrust_voltage))
    throw params.error("battery: needs battery_zero_thrust_voltage < battery_empty_voltage < battery_full_voltage "
                       "and battery_nominal_voltage > battery_zero_thrust_voltage");
  return bp;
}

template <class T>
std::optional<T> given(const Descriptor& params, const char* key) {
  return params.has(key) ? std::optional<T>(params.get<T>(key)) : std::nullopt;
}

}  // namespace

// Everything the driver reads from its parameters but the member's own formation_index, parsed
// and checked against itself once per parameter set: a swarm's members share one.
struct QuadrotorDriver::Config {
  RotorParams rotor;
  std::vector<std::string> rotor_names;
  std::vector<int> directions;  // 1 or -1 per rotor
  bool ground_effect = false;
  Vec3 wind, gust;
  double gust_start, gust_duration, turbulence_w20, min_airspeed;
  bool downwash = false;
  double downwash_c[3], downwash_range, downwash_min_dz;
  double inner_rate_hz, outer_rate_hz;
  double attitude_kp, attitude_kd, yaw_rate_kp, max_angular_acceleration, filter_gyro_weight;
  std::optional<Vec3> controller_inertia;
  std::optional<double> controller_mass, max_thrust;
  Vec3 position_kp, position_kd, position_ki;
  double integral_limit, max_tilt;  // m s, rad
  bool thrust_estimator = false;
  double estimator_tau;
  bool command_link = false;
  double angle_step, command_delay;  // rad, s
  std::optional<BatteryParams> battery;
  std::string reference;
  std::optional<Vec3> target, center;
  Vec3 offset, center_offset;
  double heading_kp, amplitude, eight_period, yaw_rate, start_time;
  std::size_t formation_size;
  double formation_radius;
  Vec3 formation_center;
  double formation_gain, formation_max_speed, formation_anchor_gain, obstacle_distance, obstacle_saturation;

  explicit Config(const Descriptor& params);
  // the text a Config is parsed from (every given parameter but formation_index); marks those read
  static std::string key(const Descriptor& params);
  // the rotors at the artifact's physic nodes, positions relative to the centre of mass
  std::vector<Rotor> rotorsOf(const Descriptor& params, const Artifact& a) const;
  // command_delay in inner-loop periods (a whole number of them)
  std::size_t commandDelayTicks(const Descriptor& params, const PluginContext& context) const;
};

QuadrotorDriver::Config::Config(const Descriptor& params) : rotor(rotorParams(params)) {
  rotor_names = words(params.get<std::string>("rotors"));
  const auto& names = rotor_names;
  const auto dirs = words(params.get<std::string>("directions"));
  if (names.size() != dirs.size() || names.size() < 4 || names.size() > kMaxRotors)
    throw params.errorAt(names.size() != dirs.size() ? "directions" : "rotors",
                         "'rotors' and 'directions' must name the same number (4 to " + std::to_string(kMaxRotors) +
                             ") of rotors");
  for (const auto& d : dirs) {
    if (d != "1" && d != "-1") throw params.errorAt("directions", "rotor directions are 1 or -1, got '" + d + "'");
    directions.push_back(d == "1" ? 1 : -1);
  }
  ground_effect = params.get<bool>("ground_effect");
  wind = params.get<Vec3>("wind");
  gust = params.get<Vec3>("gust");
  gust_start = params.get<double>("gust_start");
  gust_duration = params.get<double>("gust_duration");
  turbulence_w20 = params.get<double>("turbulence_w20");
  min_airspeed = params.get<double>("turbulence_min_airspeed");
  downwash = params.get<bool>("downwash");
  downwash_c[0] = params.get<double>("downwash_c1");
  downwash_c[1] = params.get<double>("downwash_c2");
  downwash_c[2] = params.get<double>("downwash_c3");
  downwash_range = params.get<double>("downwash_range");
  downwash_min_dz = params.get<double>("downwash_min_height");
  inner_rate_hz = params.get<double>("inner_rate_hz");
  outer_rate_hz = params.get<double>("outer_rate_hz");
  attitude_kp = params.get<double>("attitude_kp");
  attitude_kd = params.get<double>("attitude_kd");
  yaw_rate_kp = params.get<double>("yaw_rate_kp");
  max_angular_acceleration = params.get<double>("max_angular_acceleration");
  filter_gyro_weight = params.get<double>("filter_gyro_weight");
  controller_inertia = given<Vec3>(params, "controller_inertia");
  controller_mass = given<double>(params, "controller_mass");
  max_thrust = given<double>(params, "max_thrust");
  position_kp = params.get<Vec3>("position_kp");
  position_kd = params.get<Vec3>("position_kd");
  position_ki = params.get<Vec3>("position_ki");
  integral_limit = params.get<double>("integral_limit");
  max_tilt = params.get<double>("max_tilt_deg") * std::numbers::pi / 180.0;
  thrust_estimator = params.get<bool>("thrust_estimator");
  estimator_tau = params.get<double>("thrust_estimator_time_constant");
  command_link = params.get<bool>("command_link");
  angle_step = params.get<double>("command_angle_step_deg") * std::numbers::pi / 180.0;
  command_delay = params.get<double>("command_delay");
  if (params.get<bool>("battery")) battery = batteryParams(params);
  reference = params.get<std::string>("reference");
  target = given<Vec3>(params, "target");
  center = given<Vec3>(params, "center");
  offset = params.get<Vec3>("offset");
  center_offset = params.get<Vec3>("center_offset");
  heading_kp = params.get<double>("heading_kp");
  amplitude = params.get<double>("amplitude");
  eight_period = params.get<double>("eight_period");
  yaw_rate = params.get<double>("yaw_rate");
  start_time = params.get<double>("start_time");
  formation_size = static_cast<std::size_t>(params.get<std::int64_t>("formation_size"));
  formation_radius = params.get<double>("formation_radius");
  formation_center = params.get<Vec3>("formation_center");
  formation_gain = params.get<double>("formation_gain");
  formation_max_speed = params.get<double>("formation_max_speed");
  formation_anchor_gain = params.get<double>("formation_anchor_gain");
  obstacle_distance = params.get<double>("obstacle_distance");
  obstacle_saturation = params.get<double>("obstacle_saturation");
}

std::string QuadrotorDriver::Config::key(const Descriptor& params) {
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

std::vector<Rotor> QuadrotorDriver::Config::rotorsOf(const Descriptor& params, const Artifact& a) const {
  std::vector<Rotor> rotors;
  for (std::size_t i = 0; i < rotor_names.size(); ++i) {
    const PhysicNode* node = a.node(rotor_names[i]);
    if (node == nullptr)
      throw params.errorAt("rotors",
                           "no physic node '" + rotor_names[i] + "' for a rotor in artifact '" + a.name() + "'");
    rotors.push_back({node->poseInBody().position, directions[i]});
  }
  return rotors;
}

std::size_t QuadrotorDriver::Config::commandDelayTicks(const Descriptor& params, const PluginContext& context) const {
  const double inner_period =
      static_cast<double>(runsPerPeriod(inner_rate_hz, context)) * toSeconds(context.period());
  const double ticks = command_delay / inner_period;
  if (std::abs(ticks - std::round(ticks)) > 1e-6)
    throw params.errorAt("command_delay", "command_delay must be a whole number of inner-loop periods (" +
                                              std::to_string(inner_period * 1e3) + " ms)");
  return static_cast<std::size_t>(std::llround(ticks));
}

// What the rotors' places make of a Config: shared by the members of one artifact type.
struct QuadrotorDriver::Airframe {
  std::vector<Rotor> rotors;
  RotorModel rotor_model;  // at rest; each driver copies it (the copies share its constants)
  MassProperties mass;
  Mat3 inertia;                // what the inner loop assumes
  Eigen::MatrixXd mixer;       // InnerLoopParams::mixer
  double rotor_max_thrust = 0;  // N, all rotors at full speed

  // the airframe of artifact `a`, checked against what the integer inner loop can hold
  Airframe(const Config& c, const Descriptor& params, const Artifact& a)
      : rotors(c.rotorsOf(params, a)), rotor_model(rotors, c.rotor), mass(combinedMass(a.root().spec())) {
    inertia = c.controller_inertia ? Mat3(c.controller_inertia->asDiagonal()) : mass.inertia;
    const Allocation allocation(rotors, c.rotor);
    Eigen::Matrix4d scale = Eigen::Matrix4d::Identity();
    scale.topLeftCorner<3, 3>() = inertia;
    mixer = allocation.inverse() * scale;
    rotor_max_thrust = allocation.matrix().row(3).sum() * c.rotor.max_rotor_speed * c.rotor.max_rotor_speed;
    if (!mixerFitsFixedPoint(mixer, c.max_angular_acceleration, rotor_max_thrust))
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

}  // namespace

void QuadrotorDriver::validate(const Descriptor& params, const PluginContext& context) {
  const Artifact& a = *context.artifact;
  if (a.rootCount() == 0 || a.root().isStatic()) throw params.error("a quadrotor needs a dynamic physic root");
  // parsed and checked once per parameter set and artifact type (a swarm's members share them)
  const auto shared_config = context.shared<Config>(Config::key(params), [&] { return Config(params); });
  const Config& config = *shared_config;
  std::ostringstream frame_key;
  frame_key << shared_config.get() << ' ' << &a.root().spec();
  (void)context.shared<Airframe>(frame_key.str(), [&] { return Airframe(config, params, a); });
  // checked while loading, so that `ssx validate` refuses what `ssx run` would
  (void)config.commandDelayTicks(params, context);
  if (firstSensorOf<ImuMeasurement>(a) == nullptr)
    throw params.error("a quadrotor needs an IMU: add <sensor plugin=\"imu\"/> to the artifact");
  if (config.reference == "formation") {
    const auto index = params.get<std::int64_t>("formation_index");
    if (static_cast<std::size_t>(index) >= config.formation_size || static_cast<std::size_t>(index) > a.index())
      throw params.errorAt("formation_index",
                           "formation_index must be below formation_size and the members one swarm");
    if (firstSensorOf<RangeMeasurement>(a) == nullptr)
      throw params.error("reference=\"formation\" needs a range sensor on the artifact");
  }
}

void QuadrotorDriver::configure(const Descriptor& params, PluginSetup& setup) {
  Artifact& a = artifact();
  const Environment& env = environment();
  // parsed once per parameter set, and worked out once per parameter set and artifact type
  const auto config = setup.shared<Config>(Config::key(params), [&] { return Config(params); });
  const Config& c = *config;
  const RotorParams& rp = c.rotor;
  std::ostringstream frame_key;
  frame_key << config.get() << ' ' << &a.root().spec();
  const auto frame = setup.shared<Airframe>(frame_key.str(), [&] { return Airframe(c, params, a); });
  const std::vector<Rotor>& rotors = frame->rotors;
  const MassProperties& mass = frame->mass;
  com_in_root_ = -a.root().poseInBody().position;
  rotors_.emplace(frame->rotor_model);
  // ground effect: over the highest horizontal ground plane, if there is one
  ground_effect_ = c.ground_effect;
  ground_z_ = -std::numeric_limits<double>::infinity();
  for (const auto& shape : env.staticShapes()) {
    if (shape.shape.kind != Shape::Kind::Plane) continue;
    const Pose world = shape.world * shape.shape.pose;
    if ((world.orientation * Vec3::UnitZ()).z() > 1.0 - 1e-9) ground_z_ = std::max(ground_z_, world.position.z());
  }
  gains_.fill(1.0);
  // the air: mean wind, one gust, Dryden turbulence
  wind_ = c.wind;
  gust_ = c.gust;
  gust_start_ = c.gust_start;
  gust_duration_ = c.gust_duration;
  turbulence_w20_ = c.turbulence_w20;
  min_airspeed_ = c.min_airspeed;
  wind_or_gust_ = !wind_.isZero() || !gust_.isZero() || turbulence_w20_ > 0;
  downwash_ = c.downwash;
  std::copy(std::begin(c.downwash_c), std::end(c.downwash_c), downwash_c_);
  downwash_range_ = c.downwash_range;
  downwash_min_dz_ = c.downwash_min_dz;
  if (downwash_) setup.enableNeighborQueries(downwash_range_);

  // the loops run every k runs of the driver (whole numbers: checked while loading)
  const PluginContext context{&env, &a, periodSteps(), env.timestep(), {}};
  const double period = toSeconds(context.period());
  inner_runs_ = runsPerPeriod(c.inner_rate_hz, context);
  outer_runs_ = runsPerPeriod(c.outer_rate_hz, context);
  if (inner_runs_ < 1 || outer_runs_ < 1)
    throw params.error("inner_rate_hz and outer_rate_hz must not be faster than the driver runs");
  outer_dt_ = static_cast<double>(outer_runs_) * period;

  // the IMU this controller reads (required) and a pose source (optional)
  const Sensor* imu = firstSensorOf<ImuMeasurement>(a);
  if (imu == nullptr) throw params.error("a quadrotor needs an IMU: add <sensor plugin=\"imu\"/> to the artifact");
  imu_ = static_cast<const ImuMeasurement*>(&imu->latest());
  setup.subscribe<ImuMeasurement>(*imu, [this](const ImuMeasurement&) { imu_seen_ = true; });
  if (const Sensor* pose = firstSensorOf<PoseMeasurement>(a)) {
    have_pose_ = true;
    setup.subscribe<PoseMeasurement>(*pose, [this](const PoseMeasurement& m) { pose_ = m; });
  }

  // inner loop
  InnerLoopParams ip;
  ip.dt = static_cast<double>(inner_runs_) * period;
  ip.attitude_kp = c.attitude_kp;
  ip.attitude_kd = c.attitude_kd;
  ip.yaw_rate_kp = c.yaw_rate_kp;
  ip.max_angular_acceleration = c.max_angular_acceleration;
  ip.filter_gyro_weight = c.filter_gyro_weight;
  ip.gravity = -env.settings().physics.gravity.z();
  ip.inertia = frame->inertia;
  ip.min_rotor_speed = rp.min_rotor_speed;
  ip.max_rotor_speed = rp.max_rotor_speed;
  ip.mixer = frame->mixer;
  ip.max_thrust = frame->rotor_max_thrust;
  // the IMU's LSBs are known once it has been configured (it comes first in the artifact)
  ip.gyro_lsb = imu_->gyroscope_lsb > 0 ? imu_->gyroscope_lsb : ip.gyro_lsb;
  ip.accel_lsb = imu_->accelerometer_lsb > 0 ? imu_->accelerometer_lsb : ip.accel_lsb;
  // its integer gains and mixer: one copy for the members alike (the estimate is this driver's)
  char inner_key[96];
  std::snprintf(inner_key, sizeof inner_key, " %a %a %a", ip.dt, ip.gyro_lsb, ip.accel_lsb);
  inner_ = setup.shared<InnerLoopFixed>(frame_key.str() + inner_key, [&] { return InnerLoopFixed(ip); });
  estimate_ = {};

  // outer loop
  PositionParams pp;
  pp.mass = c.controller_mass.value_or(mass.mass);
  pp.gravity = ip.gravity;
  pp.kp = c.position_kp;
  pp.kd = c.position_kd;
  pp.ki = c.position_ki;
  pp.integral_limit = c.integral_limit;
  pp.max_tilt = c.max_tilt;
  pp.max_thrust = c.max_thrust.value_or(0.95 * ip.max_thrust);
  pp.min_thrust = 0.05 * pp.max_thrust;
  outer_.emplace(pp);
  controller_mass_ = pp.mass;
  thrust_estimator_ = c.thrust_estimator;
  estimator_tau_ = c.estimator_tau;
  command_link_ = c.command_link;
  angle_step_ = c.angle_step;
  command_queue_.assign(c.commandDelayTicks(params, context) + 1, InnerCommand{});
  if (c.battery) battery_.emplace(*c.battery);

  // reference source
  const Vec3 start = a.placement().position;
  hover_.position = c.target.value_or(Vec3(start + c.offset));
  // an external reference starts at the placed heading, which it holds until a set-point says otherwise
  const Vec3 placed_forward = a.placement().orientation * Vec3::UnitX();
  hover_.yaw = std::atan2(placed_forward.y(), placed_forward.x());
  heading_kp_ = c.heading_kp;
  eight_.center = c.center.value_or(Vec3(start + c.center_offset));
  eight_.amplitude = c.amplitude;
  eight_.period = c.eight_period;
  eight_.yaw_rate = c.yaw_rate;
  start_time_ = c.start_time;
  if (c.reference == "hover") {
    source_ = Source::Hover;
  } else if (c.reference == "eight_horizontal" || c.reference == "eight_vertical") {
    source_ = Source::Eight;
    eight_.vertical = c.reference == "eight_vertical";
  } else if (c.reference == "formation") {
    source_ = Source::Formation;
    formation_.size = c.formation_size;
    const auto index = params.get<std::int64_t>("formation_index");
    if (index < 0 || static_cast<std::size_t>(index) >= formation_.size || static_cast<std::size_t>(index) > a.index())
      throw params.error("formation_index must be in [0, formation_size) and the members one swarm");
    formation_index_ = static_cast<std::size_t>(index);
    formation_base_ = a.index() - formation_index_;
    formation_.radius = c.formation_radius;
    formation_.center = c.formation_center;
    formation_.gain = c.formation_gain;
    formation_.max_speed = c.formation_max_speed;
    formation_.anchor_gain = c.formation_anchor_gain;
    formation_.obstacle_distance = c.obstacle_distance;
    formation_.obstacle_saturation = c.obstacle_saturation;
    const Sensor* range = firstSensorOf<RangeMeasurement>(a);
    if (range == nullptr) throw params.error("reference=\"formation\" needs a range sensor on the artifact");
    // read in place, as the IMU: the sensor's measurement changes only when it senses, before
    // this driver's step (a copy per delivery cost 3 % of a step at 10,000 robots)
    range_ = static_cast<const RangeMeasurement*>(&range->latest());
    // room for the neighbours a robot usually has, so that flying allocates nothing; a robot
    // that meets more grows this once, to the most it has met
    desired_distance_.reserve(std::min(kTypicalNeighbours, formation_.size));
    virtual_point_ = start + c.offset;
    own_target_ = formation_.target(formation_index_);
  } else {
    source_ = Source::External;
    external_ = hover_;
  }
  current_ = reference(0.0);

  // a vehicle placed in the air starts with its rotors at hover speed
  commanded_speeds_.fill(0.0);
  if (start.z() > 0.1) {
    const double hover = std::sqrt(mass.mass * ip.gravity / (rotors.size() * rp.thrust_coefficient));
    commanded_speeds_.fill(hover);
    rotors_->setSpeeds(std::span(commanded_speeds_).first(rotors.size()));
    command_.thrust_q16 = static_cast<std::int32_t>(std::llround(mass.mass * ip.gravity * 65536.0));
  }
  // before the first delayed command arrives, the inner loop has the initial one
  std::fill(command_queue_.begin(), command_queue_.end(), command_);
}

Setpoint QuadrotorDriver::reference(double t) const {
  switch (source_) {
    case Source::Hover:
      return hover_;
    case Source::External:
      return external_;
    case Source::Formation: {
      Setpoint s;
      s.position = virtual_point_;
      s.velocity = virtual_velocity_;
      return s;
    }
    case Source::Eight: {
      // hold the curve's start until start_time, then fly it
      if (t < start_time_) {
        Setpoint s = eight_.at(0.0);
        s.velocity.setZero();
        s.acceleration.setZero();
        s.yaw_rate = 0;
        return s;
      }
      return eight_.at(t - start_time_);
    }
  }
  return hover_;
}

void QuadrotorDriver::setCommand(const Command& command) {
  if (const std::string why = refusal(command); !why.empty()) throw std::invalid_argument("quadrotor: " + why);
  const CommandLevel previous = level_;
  source_ = Source::External;
  level_ = command.level;
  switch (command.level) {
    case CommandLevel::Position:
      external_ = command.setpoint;
      break;
    case CommandLevel::Velocity:
      // the reference point starts where the vehicle is, and moves on from there while the level holds
      if (previous != CommandLevel::Velocity) velocity_point_ = artifact().state().pose.position;
      command_velocity_ = command.velocity;
      command_yaw_rate_ = command.yaw_rate;
      break;
    case CommandLevel::Attitude:
      attitude_ = overLink({command.roll, command.pitch, command.yaw_rate, command.thrust});
      command_ = toInner(attitude_);
      break;
    case CommandLevel::Rates:
      // (no serial link quantisation: the link carries angles)
      command_.roll_q12 = static_cast<std::int32_t>(std::llround(command.body_rates.x() * 4096.0));
      command_.pitch_q12 = static_cast<std::int32_t>(std::llround(command.body_rates.y() * 4096.0));
      command_.yaw_rate_q12 = static_cast<std::int32_t>(std::llround(command.body_rates.z() * 4096.0));
      command_.thrust_q16 = static_cast<std::int32_t>(std::llround(command.thrust * 65536.0));
      break;
    case CommandLevel::Rotors:
      std::copy(command.rotor_speeds.begin(), command.rotor_speeds.end(), commanded_speeds_.begin());
      break;
  }
  // the position loop's integral starts afresh when it takes over again
  if (previous > CommandLevel::Velocity && level_ <= CommandLevel::Velocity) outer_->reset();
}

AttitudeCommand QuadrotorDriver::overLink(const AttitudeCommand& c) const {
  // the serial link: thrust in 8 bits of m g / 128 (255: 2 m g), angles in whole steps
  return command_link_ ? linkCommand(c, controller_mass_, -environment().settings().physics.gravity.z(), angle_step_)
                       : c;
}

InnerCommand QuadrotorDriver::toInner(const AttitudeCommand& c) {
  InnerCommand out;
  out.roll_q12 = static_cast<std::int32_t>(std::llround(c.roll * 4096.0));
  out.pitch_q12 = static_cast<std::int32_t>(std::llround(c.pitch * 4096.0));
  out.yaw_rate_q12 = static_cast<std::int32_t>(std::llround(c.yaw_rate * 4096.0));
  out.thrust_q16 = static_cast<std::int32_t>(std::llround(c.thrust * 65536.0));
  return out;
}

// the position loop: position (motion capture or ground truth) to attitude and thrust
void QuadrotorDriver::outerLoop(const StepInfo& info) {
  // the formation starts after start_time; until then the vehicle climbs to its start + offset
  if (source_ == Source::Formation && toSeconds(info.time) >= start_time_) formationStep(outer_dt_);
  current_ = reference(toSeconds(info.time));
  BodyState truth;
  if (!have_pose_) truth = artifact().state();
  const Pose& pose = have_pose_ ? pose_.pose : truth.pose;
  const Vec3 velocity = have_pose_ ? pose_.linear_velocity : truth.linear_velocity;
  const Vec3 forward = pose.orientation * Vec3::UnitX();
  const double yaw = std::atan2(forward.y(), forward.x());
  const double roll = estimate_.roll_q20 / 1048576.0;
  const double pitch = estimate_.pitch_q20 / 1048576.0;
  if (level_ == CommandLevel::Velocity) {
    // a point moving at the commanded velocity, never more than kVelocityLeash from the vehicle
    // per axis: the velocity error acts through kd, the point's lead through kp and ki
    velocity_point_ += command_velocity_ * outer_dt_;
    velocity_point_ = pose.position + (velocity_point_ - pose.position).cwiseMin(kVelocityLeash).cwiseMax(-kVelocityLeash);
    current_ = Setpoint{velocity_point_, command_velocity_, Vec3::Zero(), yaw, command_yaw_rate_};
  }
  attitude_ = outer_->update(outer_dt_, current_, pose.position, velocity, roll, pitch, yaw);
  // an external set-point's heading is held: its yaw error, wrapped to [-pi, pi], adds a yaw
  // rate (the other references command a yaw rate only, as the TeleKyb controller does)
  if (source_ == Source::External && level_ == CommandLevel::Position)
    attitude_.yaw_rate += heading_kp_ * std::remainder(current_.yaw - yaw, 2.0 * std::numbers::pi);
  // the online thrust estimator: the specific force along the body's z axis, from the position
  // source's velocity (motion capture: no accelerometer bias), against what the commanded thrust
  // should give the mass the controller believes; the command is divided by their ratio
  if (thrust_estimator_) {
    const double g = -environment().settings().physics.gravity.z();
    const double expected = static_cast<double>(command_.thrust_q16) / 65536.0 / controller_mass_;
    if (have_last_velocity_ && expected > 0.2 * g) {
      const Vec3 specific = (velocity - last_velocity_) / outer_dt_ + Vec3(0, 0, g);
      const double along = specific.dot(pose.orientation * Vec3::UnitZ());
      thrust_ratio_ += outer_dt_ / estimator_tau_ * (along / expected - thrust_ratio_);
      thrust_ratio_ = std::clamp(thrust_ratio_, 0.5, 2.0);
    }
    last_velocity_ = velocity;
    have_last_velocity_ = true;
    attitude_.thrust /= thrust_ratio_;
  }
  // handed to the inner loop as integers (over the serial link, if there is one)
  attitude_ = overLink(attitude_);
  command_ = toInner(attitude_);
}

void QuadrotorDriver::step(const StepInfo& info) {
  const double period = info.periodSeconds();
  const std::int64_t run = info.step / periodSteps();
  PhysicNode& body = artifact().root();
  // the position loop acts at the position and velocity levels; below them the commands go to the
  // inner loop (attitude, rates) or the motors (rotors) as they were set
  if (run % outer_runs_ == 0 && level_ <= CommandLevel::Velocity) outerLoop(info);
  // inner loop: IMU counts to motor commands
  if (run % inner_runs_ == 0 && imu_seen_) {
    // the command as it arrives: command_delay late (the queue holds that many inner-loop ticks)
    // (without a delay the command passes straight through: the queue is not touched)
    if (command_queue_.size() > 1) {
      command_queue_[queue_at_] = command_;
      queue_at_ = (queue_at_ + 1) % command_queue_.size();
    }
    const InnerCommand& arrived = command_queue_.size() == 1 ? command_ : command_queue_[queue_at_];
    const InnerOutput out =
        inner_->evaluate(estimate_, imu_->gyroscope_counts, imu_->accelerometer_counts, arrived,
                         level_ == CommandLevel::Rates ? InnerMode::Rates : InnerMode::Attitude);
    estimate_ = out.estimate;
    // (at the rotors level the estimate goes on, the motors take the command's speeds)
    if (level_ != CommandLevel::Rotors)
      for (std::size_t i = 0; i < out.motors; ++i) commanded_speeds_[i] = inner_->commandToSpeed(out.motor_commands[i]);
  }
  // motors and aerodynamics, applied at the centre of mass in body axes
  rotors_->step(period, std::span(commanded_speeds_).first(rotors_->size()));
  const BodyState s = body.state();
  const Quat to_body = s.pose.orientation.conjugate();
  const BodyState& com = artifact().environment().bodyState(body.bodyIndex());
  Vec3 v_com = com.linear_velocity;
  // the body moves relative to the air: mean wind, the gust, the turbulence
  if (wind_or_gust_) {
    Vec3 air = wind_;
    const double tg = toSeconds(info.time) - gust_start_;
    if (tg >= 0 && tg <= gust_duration_) air += 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * tg / gust_duration_)) * gust_;
    if (turbulence_w20_ > 0) {
      const double height = com.pose.position.z() - (std::isfinite(ground_z_) ? ground_z_ : 0.0);
      const auto scales = DrydenTurbulence::scales(height, turbulence_w20_);
      const double airspeed = std::max((v_com - wind_).norm(), min_airspeed_);
      const Vec3 uvw = turbulence_.step(period, scales, airspeed, random());
      // u along the mean wind's horizontal direction (x without one), w up
      const Vec3 flat(wind_.x(), wind_.y(), 0);
      const Vec3 along = flat.norm() > 1e-9 ? Vec3(flat.normalized()) : Vec3(Vec3::UnitX());
      air += uvw.x() * along + uvw.y() * Vec3::UnitZ().cross(along) + uvw.z() * Vec3::UnitZ();
    }
    v_com -= air;
  }
  // robots above push this one down
  if (downwash_) {
    const Vec3 here = artifact().pose().position;
    above_.clear();  // neighbors() appends
    artifact().environment().neighbors(here, downwash_range_, above_);
    double push = 0;
    for (const auto& hit : above_) {
      if (hit.id == artifact().index()) continue;
      // rotorcraft only (reading what another artifact's driver is, not its state)
      if (dynamic_cast<const QuadrotorDriver*>(environment().artifact(hit.id).driver()) == nullptr) continue;
      const Vec3 d = hit.point - here;
      push += downwashForce(d.z(), d.head<2>().norm(), rotors_->params().rotor_radius, downwash_c_[0], downwash_c_[1],
                            downwash_c_[2], downwash_min_dz_);
    }
    if (push != 0) body.addForce(Vec3(0, 0, push), Frame::World, com_in_root_, Frame::Local);
  }
  if (ground_effect_ || battery_) {
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
      battery_->step(period, power);
      battery_gain = battery_->thrustGain();
    }
    for (std::size_t i = 0; i < rotors.size(); ++i)
      gains_[i] = battery_gain * (ground_effect_ ? groundEffectGain(com.pose.transformPoint(rotors[i].position).z() -
                                                                        ground_z_, rp.rotor_radius)
                                                 : 1.0);
    rotors_->setThrustGains(std::span(gains_).first(rotors.size()));
  }
  Vec3 force, torque;
  rotors_->wrench(to_body * v_com, to_body * s.angular_velocity, force, torque);
  body.addForce(force, Frame::Local, com_in_root_, Frame::Local);
  body.addTorque(torque, Frame::Local);
}

// the formation's virtual point: v = gain sum_j g(d_ij, d*_ij) u_ij + repulsion from whatever is too
// close + a pull towards the own target, then no approach towards anything inside its safety
// distance, saturated at a speed that drops in a crowd; integrated at the position loop's rate
// d* to a member: computed the first time it is seen, then looked up (neighbours change slowly)
double QuadrotorDriver::desiredDistance(std::size_t member) {
  auto it = std::lower_bound(desired_distance_.begin(), desired_distance_.end(), member,
                             [](const auto& e, std::size_t m) { return e.first < m; });
  if (it != desired_distance_.end() && it->first == member) return it->second;
  const double d = (own_target_ - formation_.target(member)).norm();
  desired_distance_.insert(it, {member, d});
  return d;
}

std::vector<std::string> QuadrotorDriver::metricNames() const {
  if (source_ == Source::Formation) return {"formation_error"};
  return {};
}

void QuadrotorDriver::metrics(std::vector<Metric>& out) const {
  if (source_ != Source::Formation) return;
  double sum = 0;
  std::size_t members = 0;
  for (const auto& d : seen()) {
    if (d.obstacle || d.artifact < formation_base_ || d.artifact >= formation_base_ + formation_.size) continue;
    // the pairs the shape is made of: neighbours on the target sphere within sensing range
    const double d_star = (own_target_ - formation_.target(d.artifact - formation_base_)).norm();
    if (d_star >= formation_.sensing_range) continue;
    sum += std::abs(d.relative.norm() - d_star);
    ++members;
  }
  out.push_back({"formation_error", members > 0 ? sum / static_cast<double>(members)
                                                : std::numeric_limits<double>::quiet_NaN()});
}

void QuadrotorDriver::formationStep(double dt) {
  const Formation& f = formation_;
  Vec3 v = Vec3::Zero();
  const Vec3& own_target = own_target_;
  for (const auto& d : seen()) {
    if (d.distance <= 1e-9) continue;
    const Vec3 away = -d.relative / d.relative.norm();  // u_ij, from the neighbour to this robot
    if (d.obstacle) {
      v += 2.0 * f.max_speed * f.obstacleGradient(d.distance) * away;
      continue;
    }
    // every robot close by is kept clear of; members are also held at their desired distance
    v += f.max_speed * f.clearanceGradient(d.relative.norm()) * away;
    if (d.artifact < formation_base_ || d.artifact >= formation_base_ + f.size) continue;
    const double d_star = desiredDistance(d.artifact - formation_base_);
    v += f.gain * f.pairGradient(d.relative.norm(), d_star) * away;
  }
  // v_cmd: each member knows its own place on the sphere, capped at half the top speed
  const BodyState s = artifact().state();
  Vec3 anchor = f.anchor_gain * (own_target - s.pose.position);
  if (anchor.norm() > 0.5 * f.max_speed) anchor *= 0.5 * f.max_speed / anchor.norm();
  v += anchor;
  // never approach an obstacle or robot inside its safety distance (fully inside the saturation
  // distance, partly on the way there)
  for (const auto& d : seen()) {
    const double dist = d.relative.norm();
    if (dist <= 1e-9) continue;
    const double outer = d.obstacle ? f.obstacle_distance : f.clearance;
    const double inner = d.obstacle ? f.obstacle_saturation : 0.9 * f.clearance;
    if (dist >= outer) continue;
    const Vec3 toward = d.relative / dist;
    const double approach = v.dot(toward);
    if (approach <= 0) continue;
    const double weight = std::clamp((outer - dist) / (outer - inner), 0.0, 1.0);
    v -= weight * approach * toward;
  }
  // slower in a crowd: full speed with nobody within 2 m, a crawl at 0.7 m
  double nearest = 1e9;
  for (const auto& d : seen())
    if (!d.obstacle) nearest = std::min(nearest, d.relative.norm());
  const double speed = f.max_speed * std::clamp((nearest - 0.7) / 1.3, 0.15, 1.0);
  if (v.norm() > speed) v *= speed / v.norm();
  // the virtual point stays close to the vehicle (a short leash: the velocity feed-forward does the
  // driving, so a stop in v is a stop of the vehicle)
  virtual_velocity_ = v;
  virtual_point_ = s.pose.position + (virtual_point_ - s.pose.position).cwiseMin(0.15).cwiseMax(-0.15) + v * dt;
}

namespace {

void save(StateWriter& out, const Setpoint& s) {
  out.write(s.position);
  out.write(s.velocity);
  out.write(s.acceleration);
  out.write(s.yaw);
  out.write(s.yaw_rate);
}

void load(StateReader& in, Setpoint& s) {
  in.read(s.position);
  in.read(s.velocity);
  in.read(s.acceleration);
  in.read(s.yaw);
  in.read(s.yaw_rate);
}

}  // namespace

// what changes while it flies: motors, both loops, the reference sources, what it last received
void QuadrotorDriver::saveState(StateWriter& out) const {
  // (per-rotor arrays as vectors of the rotor count: the format of the saved state)
  const std::size_t n = rotors_->size();
  const auto vector = [n](std::span<const double> v) { return std::vector<double>(v.begin(), v.begin() + n); };
  out.write(vector(rotors_->speeds()));
  out.write(vector(commanded_speeds_));
  out.write(estimate_);
  out.write(outer_->integral());
  out.write(command_);
  out.write(attitude_);
  out.write(source_);
  save(out, current_);
  save(out, external_);
  out.write(virtual_point_);
  out.write(virtual_velocity_);
  // (the range detections the formation last acted on: the sensor's own, saved again here so that
  // the format stays; on load the sensor restores them)
  ssx::save(out, range_ != nullptr ? range_->detections : std::vector<RangeMeasurement::Detection>{});
  out.write(imu_seen_);
  ssx::save(out, pose_);
  out.write(vector(gains_));
  out.write(thrust_ratio_);
  // (without a delay the queue is not kept up to date: its one entry is the current command)
  out.write(command_queue_.size() == 1 ? std::vector<InnerCommand>{command_} : command_queue_);
  out.write(static_cast<std::uint64_t>(queue_at_));
  out.write(battery_ ? battery_->charge() : 0.0);
  out.write(battery_ ? battery_->voltage() : 0.0);
  out.write(turbulence_.state());
  out.write(last_velocity_);
  out.write(have_last_velocity_);
  out.write(level_);
  out.write(command_velocity_);
  out.write(command_yaw_rate_);
  out.write(velocity_point_);
}

void QuadrotorDriver::loadState(StateReader& in) {
  std::vector<double> speeds;
  in.read(speeds);
  if (speeds.size() != rotors_->speeds().size())
    throw StateError("quadrotor: saved with " + std::to_string(speeds.size()) + " rotors, this one has " +
                     std::to_string(rotors_->speeds().size()));
  rotors_->setSpeeds(speeds);
  std::vector<double> commanded;
  in.read(commanded);
  if (commanded.size() != speeds.size()) throw StateError("quadrotor: the saved commanded speeds do not fit this driver");
  std::copy(commanded.begin(), commanded.end(), commanded_speeds_.begin());
  in.read(estimate_);
  Vec3 integral;
  in.read(integral);
  outer_->setIntegral(integral);
  in.read(command_);
  in.read(attitude_);
  Source source = Source::Hover;
  in.read(source);
  if (static_cast<int>(source) < 0 || static_cast<int>(source) > static_cast<int>(Source::Formation) ||
      (source == Source::Formation) != (source_ == Source::Formation))
    throw StateError("quadrotor: the saved reference source does not fit this driver (corrupted, or another scene)");
  source_ = source;
  load(in, current_);
  load(in, external_);
  in.read(virtual_point_);
  in.read(virtual_velocity_);
  std::vector<RangeMeasurement::Detection> detections;  // the range sensor's, restored by the sensor
  ssx::load(in, detections);
  in.read(imu_seen_);
  ssx::load(in, pose_);
  std::vector<double> gains;
  in.read(gains);
  if (gains.size() != speeds.size()) throw StateError("quadrotor: the saved thrust gains do not fit this driver");
  std::copy(gains.begin(), gains.end(), gains_.begin());
  rotors_->setThrustGains(gains);
  in.read(thrust_ratio_);
  std::vector<InnerCommand> queue;
  in.read(queue);
  const auto at = static_cast<std::size_t>(in.get<std::uint64_t>());
  if (queue.size() != command_queue_.size() || at >= queue.size())
    throw StateError("quadrotor: the saved command delay does not fit this driver");
  command_queue_ = queue;
  queue_at_ = at;
  const double charge = in.get<double>(), voltage = in.get<double>();
  if (battery_) battery_->setState(charge, voltage);
  turbulence_.setState(in.get<std::array<double, 5>>());
  in.read(last_velocity_);
  in.read(have_last_velocity_);
  CommandLevel level = CommandLevel::Position;
  in.read(level);
  if (static_cast<std::size_t>(level) >= std::size(kCommandLevels) ||
      (level != CommandLevel::Position && source_ != Source::External))
    throw StateError("quadrotor: the saved command level does not fit this driver (corrupted, or another scene)");
  level_ = level;
  in.read(command_velocity_);
  in.read(command_yaw_rate_);
  in.read(velocity_point_);
}

}  // namespace ssx::quadrotor
