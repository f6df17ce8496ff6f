#include "quadrotor_driver.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace ssx::quadrotor {

namespace {

std::vector<std::string> words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

double positive(const Descriptor& p, const char* key, double fallback) { return p.getPositive(key, fallback); }

double nonNegative(const Descriptor& p, const char* key, double fallback) {
  const double v = p.get<double>(key, fallback);
  if (v < 0) throw p.error(*p.find(key), std::string(key) + " must not be negative");
  return v;
}

}  // namespace

void QuadrotorDriver::configure(const Descriptor& params) {
  Artifact& a = artifact();
  Environment& env = environment();
  if (a.rootCount() == 0 || a.root().isStatic()) throw params.error("a quadrotor needs a dynamic physic root");

  // rotor and motor constants: the preset, then any override
  const std::string preset_name = params.get<std::string>("preset", "mk_quad");
  const auto base = preset(preset_name);
  if (!base)
    throw params.error(*params.find("preset"),
                       "unknown preset '" + preset_name + "' (mk_quad, hummingbird, crazyflie)");
  RotorParams rp = *base;
  rp.thrust_coefficient = positive(params, "thrust_coefficient", rp.thrust_coefficient);
  rp.moment_constant = positive(params, "moment_constant", rp.moment_constant);
  rp.time_constant_up = positive(params, "time_constant_up", rp.time_constant_up);
  rp.time_constant_down = positive(params, "time_constant_down", rp.time_constant_down);
  rp.max_rotor_speed = positive(params, "max_rotor_speed", rp.max_rotor_speed);
  rp.min_rotor_speed = nonNegative(params, "min_rotor_speed", rp.min_rotor_speed);
  rp.rotor_drag_coefficient = nonNegative(params, "rotor_drag_coefficient", rp.rotor_drag_coefficient);
  rp.rolling_moment_coefficient = nonNegative(params, "rolling_moment_coefficient", rp.rolling_moment_coefficient);
  rp.rotor_inertia = nonNegative(params, "rotor_inertia", rp.rotor_inertia);
  if (rp.min_rotor_speed >= rp.max_rotor_speed) throw params.error("min_rotor_speed must be below max_rotor_speed");

  // rotors at their physic nodes, positions relative to the centre of mass
  const auto names = words(params.get<std::string>("rotors", "rotor0 rotor1 rotor2 rotor3"));
  const auto dirs = words(params.get<std::string>("directions", "1 -1 1 -1"));
  if (names.size() != dirs.size() || names.size() < 4)
    throw params.error("'rotors' and 'directions' must name the same number (at least 4) of rotors");
  std::vector<Rotor> rotors;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const PhysicNode* node = a.node(names[i]);
    if (node == nullptr)
      throw params.error("no physic node '" + names[i] + "' for a rotor in artifact '" + a.name() + "'");
    if (dirs[i] != "1" && dirs[i] != "-1") throw params.error("rotor directions are 1 or -1, got '" + dirs[i] + "'");
    rotors.push_back({node->poseInBody().position, dirs[i] == "1" ? 1 : -1});
  }
  const MassProperties mass = combinedMass(a.root().spec());
  com_in_root_ = -a.root().poseInBody().position;
  rotors_.emplace(rotors, rp);
  const Allocation allocation(rotors, rp);

  // loop rates in steps of the environment
  const double tau = toSeconds(env.timestep());
  auto stepsFor = [&](const char* key, double fallback) {
    const double hz = positive(params, key, fallback);
    const auto n = static_cast<std::int64_t>(std::llround(1.0 / (hz * tau)));
    if (n < 1) throw params.error(std::string(key) + " is faster than the timestep allows");
    return n;
  };
  inner_steps_ = stepsFor("inner_rate_hz", 500.0);
  outer_steps_ = stepsFor("outer_rate_hz", 50.0);
  outer_dt_ = outer_steps_ * tau;

  // the IMU this controller reads (required) and a pose source (optional)
  for (std::size_t i = 0; i < a.sensorCount(); ++i) {
    const Sensor& s = a.sensor(i);
    if (imu_ == nullptr && dynamic_cast<const ImuMeasurement*>(&s.latest()) != nullptr) {
      imu_ = static_cast<const ImuMeasurement*>(&s.latest());
      env.subscribe<ImuMeasurement>(s, a, [this](const ImuMeasurement&) { imu_fresh_ = true; });
    } else if (!have_pose_ && dynamic_cast<const PoseMeasurement*>(&s.latest()) != nullptr) {
      have_pose_ = true;
      env.subscribe<PoseMeasurement>(s, a, [this](const PoseMeasurement& m) { pose_ = m; });
    }
  }
  if (imu_ == nullptr) throw params.error("a quadrotor needs an IMU: add <sensor plugin=\"imu\"/> to the artifact");

  // inner loop
  InnerLoopParams ip;
  ip.dt = inner_steps_ * tau;
  auto bounded = [&](const char* key, double fallback, double max) {
    const double v = positive(params, key, fallback);
    if (v > max) throw params.error(*params.find(key), std::string(key) + " must be at most " + std::to_string(max));
    return v;
  };
  ip.attitude_kp = bounded("attitude_kp", ip.attitude_kp, InnerLoopLimits::attitude_kp);
  ip.attitude_kd = bounded("attitude_kd", ip.attitude_kd, InnerLoopLimits::attitude_kd);
  ip.yaw_rate_kp = bounded("yaw_rate_kp", ip.yaw_rate_kp, InnerLoopLimits::yaw_rate_kp);
  ip.max_angular_acceleration =
      bounded("max_angular_acceleration", ip.max_angular_acceleration, InnerLoopLimits::max_angular_acceleration);
  ip.filter_gyro_weight = positive(params, "filter_gyro_weight", ip.filter_gyro_weight);
  if (ip.filter_gyro_weight > 1)
    throw params.error(*params.find("filter_gyro_weight"), "filter_gyro_weight must be at most 1");
  ip.gravity = -env.settings().physics.gravity.z();
  ip.inertia = mass.inertia;
  ip.min_rotor_speed = rp.min_rotor_speed;
  ip.max_rotor_speed = rp.max_rotor_speed;
  Eigen::Matrix4d scale = Eigen::Matrix4d::Identity();
  scale.topLeftCorner<3, 3>() = mass.inertia;
  ip.mixer = allocation.inverse() * scale;
  ip.max_thrust = allocation.matrix().row(3).sum() * rp.max_rotor_speed * rp.max_rotor_speed;
  // the IMU's LSBs are known once it has been configured (it comes first in the artifact)
  ip.gyro_lsb = imu_->gyroscope_lsb > 0 ? imu_->gyroscope_lsb : ip.gyro_lsb;
  ip.accel_lsb = imu_->accelerometer_lsb > 0 ? imu_->accelerometer_lsb : ip.accel_lsb;
  inner_.emplace(ip);

  // outer loop
  PositionParams pp;
  pp.mass = positive(params, "controller_mass", mass.mass);
  pp.gravity = ip.gravity;
  pp.kp = params.get<Vec3>("position_kp", pp.kp);
  pp.kd = params.get<Vec3>("position_kd", pp.kd);
  pp.ki = params.get<Vec3>("position_ki", pp.ki);
  pp.integral_limit = positive(params, "integral_limit", pp.integral_limit);
  pp.max_tilt = positive(params, "max_tilt_deg", 30.0) * std::numbers::pi / 180.0;
  pp.max_thrust = positive(params, "max_thrust", 0.95 * ip.max_thrust);
  pp.min_thrust = 0.05 * pp.max_thrust;
  outer_.emplace(pp);

  // reference source
  const Vec3 start = a.placement().position;
  const std::string source = params.get<std::string>("reference", "hover");
  hover_.position = params.get<Vec3>("target", Vec3(start + params.get<Vec3>("offset", Vec3::Zero())));
  eight_.center = params.get<Vec3>("center", Vec3(start + params.get<Vec3>("center_offset", Vec3::Zero())));
  eight_.amplitude = positive(params, "amplitude", eight_.amplitude);
  eight_.period = positive(params, "eight_period", eight_.period);
  eight_.yaw_rate = params.get<double>("yaw_rate", eight_.yaw_rate);
  start_time_ = params.get<double>("start_time", 0.0);
  if (source == "hover") {
    source_ = Source::Hover;
  } else if (source == "eight_horizontal" || source == "eight_vertical") {
    source_ = Source::Eight;
    eight_.vertical = source == "eight_vertical";
  } else if (source == "formation") {
    source_ = Source::Formation;
    formation_.size =
        static_cast<std::size_t>(std::max<std::int64_t>(1, params.get<std::int64_t>("formation_size", 70)));
    const auto index = params.get<std::int64_t>("formation_index", 0);
    if (index < 0 || static_cast<std::size_t>(index) >= formation_.size || static_cast<std::size_t>(index) > a.index())
      throw params.error("formation_index must be in [0, formation_size) and the members one swarm");
    formation_index_ = static_cast<std::size_t>(index);
    formation_base_ = a.index() - formation_index_;
    own_target_ = formation_.target(formation_index_);
    formation_.radius = positive(params, "formation_radius", formation_.radius);
    formation_.center = params.get<Vec3>("formation_center", formation_.center);
    formation_.gain = positive(params, "formation_gain", formation_.gain);
    formation_.max_speed = positive(params, "formation_max_speed", formation_.max_speed);
    formation_.anchor_gain = nonNegative(params, "formation_anchor_gain", formation_.anchor_gain);
    formation_.obstacle_distance = positive(params, "obstacle_distance", formation_.obstacle_distance);
    formation_.obstacle_saturation = positive(params, "obstacle_saturation", formation_.obstacle_saturation);
    bool have_range = false;
    for (std::size_t i = 0; i < a.sensorCount(); ++i) {
      const Sensor& s = a.sensor(i);
      if (dynamic_cast<const RangeMeasurement*>(&s.latest()) == nullptr) continue;
      env.subscribe<RangeMeasurement>(s, a, [this](const RangeMeasurement& m) { seen_ = m.detections; });
      have_range = true;
      break;
    }
    if (!have_range) throw params.error("reference=\"formation\" needs a range sensor on the artifact");
    virtual_point_ = start + params.get<Vec3>("offset", Vec3::Zero());
    own_target_ = formation_.target(formation_index_);
  } else if (source == "external") {
    source_ = Source::External;
    external_ = hover_;
  } else {
    throw params.error(
        *params.find("reference"),
        "unknown reference '" + source + "' (hover, eight_horizontal, eight_vertical, external, formation)");
  }
  current_ = reference(0.0);

  // a vehicle placed in the air starts with its rotors at hover speed
  commanded_speeds_.assign(rotors.size(), 0.0);
  if (start.z() > 0.1) {
    const double hover = std::sqrt(mass.mass * ip.gravity / (rotors.size() * rp.thrust_coefficient));
    rotors_->setSpeeds(std::vector<double>(rotors.size(), hover));
    commanded_speeds_.assign(rotors.size(), hover);
    command_.thrust_q16 = static_cast<std::int32_t>(std::llround(mass.mass * ip.gravity * 65536.0));
  }
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

void QuadrotorDriver::setSetpoint(const Setpoint& setpoint) {
  external_ = setpoint;
  source_ = Source::External;
}

void QuadrotorDriver::step(const StepInfo& info) {
  const double tau = toSeconds(environment().timestep());
  PhysicNode& body = artifact().root();
  // outer loop: position (motion capture or ground truth) to attitude and thrust
  if (info.step % outer_steps_ == 0) {
    // the formation starts after start_time; until then the vehicle climbs to its start + offset
    if (source_ == Source::Formation && toSeconds(info.time) >= start_time_) formationStep(outer_dt_);
    current_ = reference(toSeconds(info.time));
    BodyState truth;
    if (!have_pose_) truth = artifact().state();
    const Pose& pose = have_pose_ ? pose_.pose : truth.pose;
    const Vec3 velocity = have_pose_ ? pose_.linear_velocity : truth.linear_velocity;
    const Vec3 forward = pose.orientation * Vec3::UnitX();
    const double yaw = std::atan2(forward.y(), forward.x());
    const double roll = inner_->estimate().roll_q20 / 1048576.0;
    const double pitch = inner_->estimate().pitch_q20 / 1048576.0;
    attitude_ = outer_->update(outer_dt_, current_, pose.position, velocity, roll, pitch, yaw);
    // handed to the inner loop as integers
    command_.roll_q12 = static_cast<std::int32_t>(std::llround(attitude_.roll * 4096.0));
    command_.pitch_q12 = static_cast<std::int32_t>(std::llround(attitude_.pitch * 4096.0));
    command_.yaw_rate_q12 = static_cast<std::int32_t>(std::llround(attitude_.yaw_rate * 4096.0));
    command_.thrust_q16 = static_cast<std::int32_t>(std::llround(attitude_.thrust * 65536.0));
  }
  // inner loop: IMU counts to motor commands
  if (info.step % inner_steps_ == 0 && imu_fresh_) {
    imu_fresh_ = false;
    const InnerOutput out = inner_->step(imu_->gyroscope_counts, imu_->accelerometer_counts, command_);
    for (std::size_t i = 0; i < out.motors; ++i) commanded_speeds_[i] = inner_->commandToSpeed(out.motor_commands[i]);
  }
  // motors and aerodynamics, applied at the centre of mass in body axes
  rotors_->step(tau, commanded_speeds_);
  const BodyState s = body.state();
  const Quat to_body = s.pose.orientation.conjugate();
  const Vec3 v_com = artifact().environment().bodyState(body.bodyIndex()).linear_velocity;
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

void QuadrotorDriver::formationStep(double dt) {
  const Formation& f = formation_;
  Vec3 v = Vec3::Zero();
  const Vec3& own_target = own_target_;
  for (const auto& d : seen_) {
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
  for (const auto& d : seen_) {
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
  for (const auto& d : seen_)
    if (!d.obstacle) nearest = std::min(nearest, d.relative.norm());
  const double speed = f.max_speed * std::clamp((nearest - 0.7) / 1.3, 0.15, 1.0);
  if (v.norm() > speed) v *= speed / v.norm();
  // the virtual point stays close to the vehicle (a short leash: the velocity feed-forward does the
  // driving, so a stop in v is a stop of the vehicle)
  virtual_velocity_ = v;
  virtual_point_ = s.pose.position + (virtual_point_ - s.pose.position).cwiseMin(0.15).cwiseMax(-0.15) + v * dt;
}

}  // namespace ssx::quadrotor
