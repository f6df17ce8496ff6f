// diff_drive: a differential-drive ground robot (two driven wheels on one axle), in one of two
// models behind the same commands and odometry:
//   full:  the wheels are bodies on hinge motors (the artifact's `left_wheel` and `right_wheel`
//          nodes); they roll on the ground with its friction, so they can slip; the encoders read
//          the hinges.
//   swarm: the robot is one body, driven each step to the twist its wheels would give by a force
//          and a torque of at most `max_force` and `max_torque` (as ARGoS's 2D dynamics drives a
//          foot-bot), held on its plane (its height and upright) by the same means; it touches
//          other bodies in 3D but not the floor, so it is cheap; the encoders read the wheels the
//          body's motion would turn.
// Commands: `wheels` (left, right wheel speeds, rad/s) or `velocity` (the velocity's component
// along the heading, and the yaw rate), clamped to `max_wheel_speed` (a velocity command keeps
// its curvature). Odometry: ssx::OdometryInterface, dead-reckoned from the encoders.
//
// `controller="diffusion"`: the robot wanders and avoids what its first proximity sensor sees, as
// ARGoS's foot-bot diffusion example does: the readings summed as vectors along their rays; when
// their direction is within `diffusion_angle` of straight ahead and their length below
// `diffusion_delta`, both wheels at `cruise_speed`; otherwise it turns away on the spot's far wheel.
//
// `controller="beeclust"`: BEECLUST (Schmickl et al.), cue-based aggregation. It wanders as in
// diffusion; when its range-and-bearing board hears a robot nearer than `meet_range`, it stops and
// waits `wait_max * c^2 / (c^2 + cue_theta)` s, c the darkness its first ground sensor reads
// (1 - grey), then turns on the spot by a random angle and wanders again. Robots meeting on a dark
// spot wait long there: they gather on it.
//
// `controller="foraging"`: central-place foraging. Items broadcast `item_code` as the first byte
// of their range-and-bearing payload (range_and_bearing `data`); the nest is floor its ground
// sensor reads at least `nest_level` on. The robot wanders (diffusion) until it hears an item that
// nobody holds, steers to it, and within `grab_range` holds it by a fixed joint (PhysicNode::attach);
// then it heads home by path integration (the mean of where its odometry had it in the nest), lets
// go once in the nest, turns away and goes back to where it found the item (site fidelity, as
// foraging ants do), searching from there. Obstacles seen on the way make it diffuse.
//
// `controller="twist"`: drives at a constant `twist` (forward speed and yaw rate) from the start: a
// circle, or a straight line (a scripted ground robot for air-ground scenes).
// A command from outside takes over from any controller.
//
// Parameters: kParameters below, or `ssx plugins --params diff_drive`.
#include "../common/hold.hpp"

#include <ssx/artifact.hpp>
#include <ssx/command.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/odometry.hpp>
#include <ssx/plugin_abi.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ssx::plugins {

namespace {

constexpr double kPi = std::numbers::pi;

double yawOf(const Quat& q) {
  return std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()));
}

double wrap(double a) {
  a = std::remainder(a, 2 * kPi);
  return a <= -kPi ? a + 2 * kPi : a;
}

}  // namespace

class DiffDrive final : public Driver, public CommandInterface, public OdometryInterface {
 public:
  static constexpr const char* kDoc =
      "a differential-drive ground robot: wheels on hinge motors (full) or one body driven to the wheels' twist (swarm)";
  static constexpr ssx_plugin_param kDriveParameters[] = {
      param::choice("model", "swarm", "swarm full",
                    "full: wheel bodies on hinge motors, rolling with friction; swarm: one body driven to the wheels' "
                    "twist with limited force and torque"),
      param::required(param::real("wheel_radius", "", "m", param::positive() & param::atMost(10), "wheel radius")),
      param::required(param::real("axle_length", "", "m", param::positive() & param::atMost(100),
                                  "distance between the two wheels' contact points")),
      param::required(param::real("max_wheel_speed", "", "rad/s", param::positive() & param::atMost(1e4),
                                  "the fastest a wheel turns, either way")),
      param::text("left_wheel", "", "full model: the left wheel's node (a hinge with a motor; positive turns it forward)"),
      param::text("right_wheel", "", "full model: the right wheel's node"),
      param::real("max_force", "0", "N", param::nonNegative(),
                  "swarm model: the largest force driving the body to the wheels' velocity; 0: friction times weight"),
      param::real("max_torque", "0", "N m", param::nonNegative(),
                  "swarm model: the largest torque driving its yaw rate; 0: max_force times half the axle length"),
      param::real("encoder_noise", "0", "rad/s", param::nonNegative(),
                  "standard deviation of each wheel speed the encoders measure, per driver step"),
      param::choice("controller", "none", "none diffusion beeclust foraging twist",
                    "none: commands from outside; diffusion: wander, turning away from what the proximity sensor "
                    "sees; beeclust: wander, and wait where robots meet, longer on darker floor; foraging: carry "
                    "items heard over range-and-bearing to the nest; twist: drive at a constant twist"),
      param::vec3("twist", "0 0 0", "", param::any(),
                  "twist: 'V W 0', forward speed (m/s) and yaw rate (rad/s) from the start"),
      param::real("cruise_speed", "0", "rad/s", param::nonNegative(),
                  "diffusion: wheel speed going straight (0: max_wheel_speed)"),
      param::real("diffusion_delta", "0.1", "", param::positive(), "diffusion: obstacle vector length that makes it turn"),
      param::real("diffusion_angle", "5", "deg", param::between(0, 180),
                  "diffusion: obstacles within this of straight ahead make it turn"),
      param::real("meet_range", "0.1", "m", param::positive(), "beeclust: a robot heard nearer than this is met"),
      param::real("wait_max", "60", "s", param::nonNegative(), "beeclust: the longest wait, on the darkest floor"),
      param::real("cue_theta", "0.1", "", param::positive(), "beeclust: the darkness squared at which it waits half as long"),
      param::integer("item_code", "1", param::between(1, 255), "foraging: the first payload byte items send"),
      param::real("grab_range", "0.07", "m", param::positive(), "foraging: an item heard nearer than this is taken"),
      param::real("nest_level", "0.9", "", param::between(0, 1), "foraging: the grey level (at least) of the nest's floor"),
  };
  static constexpr auto kParameters = param::join(param::part("drive", kDriveParameters), param::part("hold", kHoldParameters));

  static void validate(const Descriptor& params, const PluginContext& context) {
    const Artifact& a = *context.artifact;
    if (a.rootCount() == 0 || a.root().isStatic()) throw params.error("diff_drive needs a dynamic physic root");
    const std::string controller = params.get<std::string>("controller");
    if (controller != "none" && controller != "twist" && sensorOf<ProximityMeasurement>(a) < 0)
      throw params.errorAt("controller", "the " + controller + " controller needs a proximity sensor on the artifact");
    if ((controller == "beeclust" || controller == "foraging") &&
        (sensorOf<RangeBearingMeasurement>(a) < 0 || sensorOf<GroundMeasurement>(a) < 0))
      throw params.errorAt("controller", "the " + controller + " controller needs a range_and_bearing and a ground sensor on the artifact");
    if (params.get<std::string>("model") != "full") return;
    for (const char* key : {"left_wheel", "right_wheel"}) {
      const std::string name = params.get<std::string>(key, "");
      if (name.empty()) throw params.error(std::string("the full model needs '") + key + "' (the wheel's node)");
      const PhysicNode* n = a.node(name);
      if (n == nullptr) throw params.errorAt(key, "no physic node '" + name + "' in this artifact");
      if (n->joint().kind != JointSpec::Kind::Hinge || !(n->joint().max_effort > 0))
        throw params.errorAt(key, "node '" + name + "' must be joined by a hinge with a motor (max_torque)");
    }
  }

  void configure(const Descriptor& params, PluginSetup&) override {
    hold_.configure(params, artifact());
    Artifact& a = artifact();
    full_ = params.get<std::string>("model") == "full";
    radius_ = params.get<double>("wheel_radius");
    axle_ = params.get<double>("axle_length");
    max_wheel_ = params.get<double>("max_wheel_speed");
    noise_ = params.get<double>("encoder_noise");
    const PhysicsSettings& physics = environment().settings().physics;
    gravity_ = physics.gravity;
    const MassProperties m = bodyMass(a.root().spec());
    mass_ = m.mass;
    inertia_ = m.inertia;
    max_force_ = params.get<double>("max_force");
    if (max_force_ == 0) max_force_ = physics.friction * mass_ * gravity_.norm();
    max_torque_ = params.get<double>("max_torque");
    if (max_torque_ == 0) max_torque_ = max_force_ * axle_ / 2;
    if (full_) {
      left_ = a.node(params.get<std::string>("left_wheel"));
      right_ = a.node(params.get<std::string>("right_wheel"));
    }
    diffusion_ = params.get<std::string>("controller") != "none" && params.get<std::string>("controller") != "twist";
    if (params.get<std::string>("controller") == "twist") {
      const Vec3 twist = params.get<Vec3>("twist");
      setWheels((twist.x() - twist.y() * axle_ / 2) / radius_, (twist.x() + twist.y() * axle_ / 2) / radius_);
    }
    beeclust_ = params.get<std::string>("controller") == "beeclust";
    foraging_ = params.get<std::string>("controller") == "foraging";
    item_code_ = static_cast<std::uint8_t>(params.get<std::int64_t>("item_code"));
    grab_range_ = params.get<double>("grab_range");
    nest_level_ = params.get<double>("nest_level");
    meet_range_ = params.get<double>("meet_range");
    wait_max_ = params.get<double>("wait_max");
    theta_ = params.get<double>("cue_theta");
    board_ = sensorOf<RangeBearingMeasurement>(a);
    ground_ = sensorOf<GroundMeasurement>(a);
    cruise_ = params.get<double>("cruise_speed");
    if (cruise_ == 0) cruise_ = max_wheel_;
    delta_ = params.get<double>("diffusion_delta");
    straight_ = params.get<double>("diffusion_angle") * kPi / 180;
    proximity_ = sensorOf<ProximityMeasurement>(a);
    const BodyState start = a.root().state();
    height_ = start.pose.position.z();
    start_ = Pose{start.pose.position, Quat(Eigen::AngleAxisd(yawOf(start.pose.orientation), Vec3::UnitZ()))};
  }

  // --- commands ---
  bool acceptsCommand(CommandLevel level) const override {
    return level == CommandLevel::Wheels || level == CommandLevel::Velocity;
  }
  std::size_t rotorCount() const override { return 0; }
  void setCommand(const Command& c) override {
    if (const std::string why = refusal(c); !why.empty()) throw std::invalid_argument(why);
    level_ = c.level;
    diffusion_ = false;  // a command from outside takes over
    if (c.level == CommandLevel::Wheels) {
      setWheels(c.left_wheel, c.right_wheel);
      return;
    }
    // the velocity's part along the heading now, and the yaw rate
    const double yaw = yawOf(artifact().root().pose().orientation);
    const double v = c.velocity.x() * std::cos(yaw) + c.velocity.y() * std::sin(yaw);
    setWheels((v - c.yaw_rate * axle_ / 2) / radius_, (v + c.yaw_rate * axle_ / 2) / radius_);
  }
  CommandLevel commandLevel() const override { return level_; }
  Command currentCommand() const override { return Command::wheels(left_cmd_, right_cmd_); }
  Setpoint currentSetpoint() const override {
    Setpoint s;
    s.position = artifact().root().pose().position;
    s.yaw = yawOf(artifact().root().pose().orientation);
    return s;
  }

  Odometry odometry() const override { return odometry_; }

  void saveState(StateWriter& out) const override {
    out.write(left_cmd_);
    out.write(right_cmd_);
    out.write(static_cast<std::uint8_t>(level_));
    out.write(diffusion_);
    out.write(static_cast<std::uint8_t>(phase_));
    out.write(until_);
    out.write(turn_);
    out.bytes(&odometry_, sizeof odometry_);
    out.write(static_cast<std::int64_t>(carrying_));
    out.write(home_x_);
    out.write(home_y_);
    out.write(has_home_);
    out.write(site_x_);
    out.write(site_y_);
    out.write(has_site_);
    out.write(lost_until_);
  }
  void loadState(StateReader& in) override {
    in.read(left_cmd_);
    in.read(right_cmd_);
    level_ = static_cast<CommandLevel>(in.get<std::uint8_t>());
    in.read(diffusion_);
    phase_ = static_cast<Phase>(in.get<std::uint8_t>() % 3);
    in.read(until_);
    in.read(turn_);
    in.bytes(&odometry_, sizeof odometry_);
    carrying_ = in.get<std::int64_t>();
    in.read(home_x_);
    in.read(home_y_);
    in.read(has_home_);
    in.read(site_x_);
    in.read(site_y_);
    in.read(has_site_);
    in.read(lost_until_);
  }

  void step(const StepInfo& info) override {
    hold_.step(info);
    const double dt = toSeconds(info.period);
    if (foraging_ && diffusion_) {
      forage(toSeconds(info.time));
    } else if (beeclust_ && diffusion_) {
      beeclust(toSeconds(info.time));
    } else if (diffusion_) {
      diffuse();
    }
    if (full_) {
      left_->setJointVelocity(left_cmd_);
      right_->setJointVelocity(right_cmd_);
    } else {
      drive(dt);
    }
    measure(dt);
  }

 private:
  template <class M>
  static int sensorOf(const Artifact& a) {
    for (std::size_t i = 0; i < a.sensorCount(); ++i)
      if (dynamic_cast<const M*>(&a.sensor(i).latest()) != nullptr) return static_cast<int>(i);
    return -1;
  }

  // BEECLUST: wander; on meeting a robot, wait as long as the floor is dark; then turn away
  void beeclust(double t) {
    if (phase_ == Phase::Wait) {
      if (t < until_) {
        setWheels(0, 0);
        return;
      }
      // a random turn on the spot, either way, up to half a turn
      phase_ = Phase::Turn;
      const double angle = random().uniform(-kPi, kPi);
      turn_ = angle >= 0 ? 1.0 : -1.0;
      until_ = t + std::abs(angle) * axle_ / (2 * radius_ * cruise_);
    }
    if (phase_ == Phase::Turn) {
      if (t < until_) {
        setWheels(-turn_ * cruise_, turn_ * cruise_);
        return;
      }
      phase_ = Phase::Walk;
      until_ = t + 1.0;  // walks on for a second before it can stop again (leaves whom it met)
    }
    const auto& heard = static_cast<const RangeBearingMeasurement&>(artifact().sensor(static_cast<std::size_t>(board_)).latest());
    const bool met = t >= until_ && std::any_of(heard.messages.begin(), heard.messages.end(),
                                                 [&](const RangeBearingMeasurement::Message& m) { return m.range < meet_range_; });
    if (!met) {
      diffuse();
      return;
    }
    const auto& floor = static_cast<const GroundMeasurement&>(artifact().sensor(static_cast<std::size_t>(ground_)).latest());
    const double cue = floor.readings.empty() ? 0.0 : 1.0 - floor.readings[0];
    phase_ = Phase::Wait;
    until_ = t + wait_max_ * cue * cue / (cue * cue + theta_);
    setWheels(0, 0);
  }

  // foraging: search (wander, steer to an item heard), carry it home, let go in the nest
  void forage(double t) {
    const auto& floor = static_cast<const GroundMeasurement&>(artifact().sensor(static_cast<std::size_t>(ground_)).latest());
    const bool in_nest = !floor.readings.empty() && floor.readings[0] >= nest_level_;
    if (in_nest) {
      // home: a running mean of where odometry had it in the nest (its middle, as it saw it)
      const double a = has_home_ ? 0.02 : 1.0;
      home_x_ += a * (odometry_.x - home_x_);
      home_y_ += a * (odometry_.y - home_y_);
      has_home_ = true;
    }
    PhysicNode& hand = artifact().root();
    if (carrying_ >= 0) {
      // two robots took one item in the same step: each lets go at random until one holds it
      const PhysicNode& item = environment().artifact(static_cast<std::size_t>(carrying_)).root();
      const bool shared = item.attachments() > 1 && random().uniform() < 0.5;
      if (in_nest || shared || (hand.attachments() == 0 && t >= until_)) {
        hand.release();
        carrying_ = -1;
        if (in_nest) {  // delivered: turn about, roughly, and search again
          phase_ = Phase::Turn;
          turn_ = random().uniform() < 0.5 ? 1.0 : -1.0;
          until_ = t + random().uniform(0.6 * kPi, kPi) * axle_ / (2 * radius_ * cruise_);
        }
        setWheels(0, 0);
        return;
      }
      const double dx = home_x_ - odometry_.x, dy = home_y_ - odometry_.y;
      // at the nest as it remembers it but not in it (odometry drifts when it is pushed): it
      // wanders for a while before it heads there again
      if (has_home_ && std::hypot(dx, dy) < 0.05) lost_until_ = t + 10.0;
      if (!has_home_ || t < lost_until_)
        diffuse();
      else if (!turnFromObstacle())
        steer(wrap(std::atan2(dy, dx) - odometry_.yaw));
      return;
    }
    if (phase_ == Phase::Turn) {
      if (t < until_) {
        setWheels(-turn_ * cruise_, turn_ * cruise_);
        return;
      }
      phase_ = Phase::Walk;
    }
    // the nearest item heard that nobody holds (none taken in the nest: it is being delivered)
    const auto& heard = static_cast<const RangeBearingMeasurement&>(artifact().sensor(static_cast<std::size_t>(board_)).latest());
    const RangeBearingMeasurement::Message* nearest = nullptr;
    for (const auto& m : heard.messages) {
      if (m.data.empty() || m.data[0] != item_code_ || (nearest != nullptr && m.range >= nearest->range)) continue;
      if (environment().artifact(m.sender).root().attachments() == 0) nearest = &m;
    }
    if (nearest == nullptr || in_nest) {
      // back to where the last item was found, then search about there
      if (has_site_ && std::hypot(site_x_ - odometry_.x, site_y_ - odometry_.y) < 0.1) has_site_ = false;
      if (!has_site_)
        diffuse();
      else if (!turnFromObstacle())
        steer(wrap(std::atan2(site_y_ - odometry_.y, site_x_ - odometry_.x) - odometry_.yaw));
      return;
    }
    if (nearest->range < grab_range_) {
      hand.attach(environment().artifact(nearest->sender).root());
      site_x_ = odometry_.x;
      site_y_ = odometry_.y;
      has_site_ = true;
      carrying_ = static_cast<std::int64_t>(nearest->sender);
      until_ = t + 0.1;  // (the hold is made before the next step's physics)
      setWheels(0, 0);
      return;
    }
    if (!turnFromObstacle()) steer(nearest->bearing);
  }

  // toward a bearing (rad, positive: left): on the spot when far off, else in an arc
  void steer(double bearing) {
    if (std::abs(bearing) > 0.6) {
      setWheels(bearing > 0 ? -cruise_ : cruise_, bearing > 0 ? cruise_ : -cruise_);
      return;
    }
    const double k = bearing / 0.6;
    setWheels(cruise_ * (1 - k), cruise_ * (1 + k));
  }

  // the readings as vectors along their rays, summed: their direction and mean length
  void obstacle(double& angle, double& length) const {
    const auto& m = static_cast<const ProximityMeasurement&>(artifact().sensor(static_cast<std::size_t>(proximity_)).latest());
    double x = 0, y = 0;
    for (std::size_t k = 0; k < m.readings.size() && k < m.angles.size(); ++k) {
      x += m.readings[k] * std::cos(m.angles[k]);
      y += m.readings[k] * std::sin(m.angles[k]);
    }
    const double n = static_cast<double>(std::max<std::size_t>(1, m.readings.size()));
    angle = std::atan2(y, x);
    length = std::hypot(x, y) / n;
  }

  // ARGoS's diffusion: turns from what the proximity sensor sees (the readings as vectors along
  // their rays, summed), else straight on
  void diffuse() {
    if (!turnFromObstacle()) setWheels(cruise_, cruise_);
  }
  // turns away, as diffusion does, when the proximity sensor sees something ahead or near; false
  // (the wheels left alone) when the way is clear
  bool turnFromObstacle() {
    double angle = 0, length = 0;
    obstacle(angle, length);
    if (std::abs(angle) <= straight_ && length < delta_) return false;
    if (angle > 0)
      setWheels(cruise_, 0);  // something on the left: turn right
    else
      setWheels(0, cruise_);
    return true;
  }

  // wheel speeds within the limit; both scaled alike, so that the path's curvature is kept
  void setWheels(double left, double right) {
    const double fastest = std::max(std::abs(left), std::abs(right));
    const double scale = fastest > max_wheel_ ? max_wheel_ / fastest : 1.0;
    left_cmd_ = left * scale;
    right_cmd_ = right * scale;
  }

  // the swarm model: the body driven to the wheels' twist, and held on its plane, each within one step
  void drive(double dt) {
    PhysicNode& root = artifact().root();
    const BodyState body = environment().bodyState(root.bodyIndex());  // at the centre of mass
    const Quat& q = body.pose.orientation;
    const double yaw = yawOf(q);
    const Vec3 forward(std::cos(yaw), std::sin(yaw), 0);
    const double v = radius_ * (left_cmd_ + right_cmd_) / 2;
    const double w = radius_ * (right_cmd_ - left_cmd_) / axle_;
    // in the plane: the velocity the wheels give (no sideways slip), with at most max_force
    Vec3 change = v * forward - Vec3(body.linear_velocity.x(), body.linear_velocity.y(), 0);
    Vec3 force = mass_ * change / dt;
    if (force.norm() > max_force_) force *= max_force_ / force.norm();
    // its height and upright: held (the weight carried), as the floor and its wheels would
    const double root_z = root.pose().position.z();
    force.z() = mass_ * ((height_ - root_z) / dt - body.linear_velocity.z()) / dt - mass_ * gravity_.z();
    Quat upright(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
    Quat tilt = upright * q.conjugate();
    if (tilt.w() < 0) tilt.coeffs() = -tilt.coeffs();
    const Eigen::AngleAxisd aa(tilt);
    Vec3 target = aa.angle() * aa.axis() / dt;
    target.z() = w;
    const Mat3 r = q.toRotationMatrix();
    const Mat3 inertia = r * inertia_ * r.transpose();
    Vec3 torque = inertia * (target - body.angular_velocity) / dt;
    torque.z() = std::clamp(torque.z(), -max_torque_, max_torque_);
    root.addForce(force, Frame::World, body.pose.position, Frame::World);
    root.addTorque(torque);
  }

  // the encoders, and the pose dead-reckoned from them (midpoint heading)
  void measure(double dt) {
    double left = 0, right = 0;
    if (full_) {
      left = left_->jointVelocity();
      right = right_->jointVelocity();
    } else {
      const BodyState s = artifact().root().state();
      const double yaw = yawOf(s.pose.orientation);
      const double v = s.linear_velocity.x() * std::cos(yaw) + s.linear_velocity.y() * std::sin(yaw);
      left = (v - s.angular_velocity.z() * axle_ / 2) / radius_;
      right = (v + s.angular_velocity.z() * axle_ / 2) / radius_;
    }
    if (noise_ > 0) {
      left += random().normal(0.0, noise_);
      right += random().normal(0.0, noise_);
    }
    Odometry& o = odometry_;
    o.left_speed = left;
    o.right_speed = right;
    o.left_angle += left * dt;
    o.right_angle += right * dt;
    o.forward = radius_ * (left + right) / 2;
    o.yaw_rate = radius_ * (right - left) / axle_;
    const double mid = o.yaw + o.yaw_rate * dt / 2;
    o.x += o.forward * std::cos(mid) * dt;
    o.y += o.forward * std::sin(mid) * dt;
    o.yaw = wrap(o.yaw + o.yaw_rate * dt);
  }

  bool full_ = false;
  bool diffusion_ = false;  // a controller drives it (diffusion, or beeclust with it)
  bool beeclust_ = false;
  bool foraging_ = false;
  std::uint8_t item_code_ = 1;
  double grab_range_ = 0, nest_level_ = 0;
  std::int64_t carrying_ = -1;  // the item's artifact index, or -1
  double home_x_ = 0, home_y_ = 0;  // where odometry last had it in the nest
  bool has_home_ = false;
  double site_x_ = 0, site_y_ = 0;  // where odometry had it when it last took an item
  bool has_site_ = false;
  double lost_until_ = 0;  // carrying, it wanders until then (it did not find the nest where it thought)
  enum class Phase : std::uint8_t { Walk, Wait, Turn };
  Phase phase_ = Phase::Walk;
  double until_ = 0, turn_ = 1, meet_range_ = 0, wait_max_ = 0, theta_ = 0;
  int board_ = -1, ground_ = -1;
  int proximity_ = -1;
  double cruise_ = 0, delta_ = 0, straight_ = 0;
  double radius_ = 0, axle_ = 0, max_wheel_ = 0, noise_ = 0, mass_ = 0, max_force_ = 0, max_torque_ = 0, height_ = 0;
  Mat3 inertia_ = Mat3::Identity();
  Vec3 gravity_ = Vec3::Zero();
  Pose start_;
  PhysicNode* left_ = nullptr;
  PhysicNode* right_ = nullptr;
  double left_cmd_ = 0, right_cmd_ = 0;
  CommandLevel level_ = CommandLevel::Wheels;
  Hold hold_;
  Odometry odometry_;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_DRIVER(ssx::plugins::DiffDrive, "diff_drive"));
