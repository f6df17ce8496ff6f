#include "behaviours.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ssx::ground {

namespace {

constexpr double kPi = std::numbers::pi;

// ARGoS's diffusion: turns from what the proximity sensor sees, else straight on. The base of the
// behaviours that wander.
class Diffusion : public GroundController {
 public:
  Diffusion(const Descriptor& params, const Artifact& a, const DriveModel& drive)
      : proximity_(sensorOf<ProximityMeasurement>(a)),
        cruise_(params.get<double>("cruise_speed") > 0 ? params.get<double>("cruise_speed") : drive.maxWheelSpeed()),
        delta_(params.get<double>("diffusion_delta")),
        straight_(params.get<double>("diffusion_angle") * kPi / 180) {}

  void step(double, GroundInputs& in) override { diffuse(in); }

 protected:
  void diffuse(GroundInputs& in) const {
    if (!turnFromObstacle(in)) in.drive.setWheels(cruise_, cruise_);
  }
  // turns away, as diffusion does, when the proximity sensor sees something ahead or near; false
  // (the wheels left alone) when the way is clear
  bool turnFromObstacle(GroundInputs& in) const {
    // the readings as vectors along their rays, summed: their direction and mean length
    const auto& m = latestOf<ProximityMeasurement>(in.artifact, proximity_);
    double x = 0, y = 0;
    for (std::size_t k = 0; k < m.readings.size() && k < m.angles.size(); ++k) {
      x += m.readings[k] * std::cos(m.angles[k]);
      y += m.readings[k] * std::sin(m.angles[k]);
    }
    const double n = static_cast<double>(std::max<std::size_t>(1, m.readings.size()));
    const double angle = std::atan2(y, x), length = std::hypot(x, y) / n;
    if (std::abs(angle) <= straight_ && length < delta_) return false;
    if (angle > 0)
      in.drive.setWheels(cruise_, 0);  // something on the left: turn right
    else
      in.drive.setWheels(0, cruise_);
    return true;
  }
  // toward a bearing (rad, positive: left): on the spot when far off, else in an arc
  void steer(GroundInputs& in, double bearing) const {
    if (std::abs(bearing) > 0.6) {
      in.drive.setWheels(bearing > 0 ? -cruise_ : cruise_, bearing > 0 ? cruise_ : -cruise_);
      return;
    }
    const double k = bearing / 0.6;
    in.drive.setWheels(cruise_ * (1 - k), cruise_ * (1 + k));
  }
  // the time a turn on the spot by `angle` takes at cruise speed
  double turnTime(double angle, const DriveModel& drive) const {
    return std::abs(angle) * drive.axleLength() / (2 * drive.wheelRadius() * cruise_);
  }

  int proximity_;
  double cruise_, delta_, straight_;
};

// a wanderer that hears robots and items (range and bearing) and reads the floor, and between its
// walks waits or turns on the spot until a time: what BEECLUST and foraging share, state included
class Roaming : public Diffusion {
 public:
  Roaming(const Descriptor& params, const Artifact& a, const DriveModel& drive)
      : Diffusion(params, a, drive),
        board_(sensorOf<RangeBearingMeasurement>(a)),
        ground_(sensorOf<GroundMeasurement>(a)) {}
  void saveState(StateWriter& out) const override {
    out.write(static_cast<std::uint8_t>(phase_));
    out.write(until_);
    out.write(turn_);
  }
  void loadState(StateReader& in) override {
    phase_ = static_cast<Phase>(in.get<std::uint8_t>() % 3);
    in.read(until_);
    in.read(turn_);
  }

 protected:
  enum class Phase : std::uint8_t { Walk, Wait, Turn };
  int board_, ground_;
  Phase phase_ = Phase::Walk;
  double until_ = 0, turn_ = 1;  // the phase lasts until then; the turn's way (1: left)
};

// BEECLUST: wander; on meeting a robot, wait as long as the floor is dark; then turn away
class BeeClust final : public Roaming {
 public:
  BeeClust(const Descriptor& params, const Artifact& a, const DriveModel& drive)
      : Roaming(params, a, drive),
        meet_range_(params.get<double>("meet_range")),
        wait_max_(params.get<double>("wait_max")),
        theta_(params.get<double>("cue_theta")) {}

  void step(double t, GroundInputs& in) override {
    if (phase_ == Phase::Wait) {
      if (t < until_) {
        in.drive.setWheels(0, 0);
        return;
      }
      // a random turn on the spot, either way, up to half a turn
      phase_ = Phase::Turn;
      const double angle = in.random.uniform(-kPi, kPi);
      turn_ = angle >= 0 ? 1.0 : -1.0;
      until_ = t + turnTime(angle, in.drive);
    }
    if (phase_ == Phase::Turn) {
      if (t < until_) {
        in.drive.setWheels(-turn_ * cruise_, turn_ * cruise_);
        return;
      }
      phase_ = Phase::Walk;
      until_ = t + 1.0;  // walks on for a second before it can stop again (leaves whom it met)
    }
    const auto& heard = latestOf<RangeBearingMeasurement>(in.artifact, board_);
    const bool met =
        t >= until_ && std::any_of(heard.messages.begin(), heard.messages.end(),
                                   [&](const RangeBearingMeasurement::Message& m) { return m.range < meet_range_; });
    if (!met) {
      diffuse(in);
      return;
    }
    const auto& floor = latestOf<GroundMeasurement>(in.artifact, ground_);
    const double cue = floor.readings.empty() ? 0.0 : 1.0 - floor.readings[0];
    phase_ = Phase::Wait;
    until_ = t + wait_max_ * cue * cue / (cue * cue + theta_);
    in.drive.setWheels(0, 0);
  }

 private:
  double meet_range_, wait_max_, theta_;
};

// foraging: search (wander, steer to an item heard), carry it home, let go in the nest
class Foraging final : public Roaming {
 public:
  Foraging(const Descriptor& params, const Artifact& a, const DriveModel& drive)
      : Roaming(params, a, drive),
        item_code_(static_cast<std::uint8_t>(params.get<std::int64_t>("item_code"))),
        grab_range_(params.get<double>("grab_range")),
        nest_level_(params.get<double>("nest_level")) {}

  void step(double t, GroundInputs& in) override {
    const Odometry& odometry = in.odometry;
    const Environment& env = in.environment;
    const auto& floor = latestOf<GroundMeasurement>(in.artifact, ground_);
    const bool in_nest = !floor.readings.empty() && floor.readings[0] >= nest_level_;
    if (in_nest) {
      // home: a running mean of where odometry had it in the nest (its middle, as it saw it)
      const double a = has_home_ ? 0.02 : 1.0;
      home_x_ += a * (odometry.x - home_x_);
      home_y_ += a * (odometry.y - home_y_);
      has_home_ = true;
    }
    PhysicNode& hand = in.artifact.root();
    if (carrying_ >= 0) {
      // two robots took one item in the same step: each lets go at random until one holds it
      const PhysicNode& item = env.artifact(static_cast<std::size_t>(carrying_)).root();
      const bool shared = item.attachments() > 1 && in.random.uniform() < 0.5;
      if (in_nest || shared || (hand.attachments() == 0 && t >= until_)) {
        hand.release();
        carrying_ = -1;
        if (in_nest) {  // delivered: turn about, roughly, and search again
          phase_ = Phase::Turn;
          turn_ = in.random.uniform() < 0.5 ? 1.0 : -1.0;
          until_ = t + turnTime(in.random.uniform(0.6 * kPi, kPi), in.drive);
        }
        in.drive.setWheels(0, 0);
        return;
      }
      const double dx = home_x_ - odometry.x, dy = home_y_ - odometry.y;
      // at the nest as it remembers it but not in it (odometry drifts when it is pushed): it
      // wanders for a while before it heads there again
      if (has_home_ && std::hypot(dx, dy) < 0.05) lost_until_ = t + 10.0;
      if (!has_home_ || t < lost_until_)
        diffuse(in);
      else if (!turnFromObstacle(in))
        steer(in, wrapAngle(std::atan2(dy, dx) - odometry.yaw));
      return;
    }
    if (phase_ == Phase::Turn) {
      if (t < until_) {
        in.drive.setWheels(-turn_ * cruise_, turn_ * cruise_);
        return;
      }
      phase_ = Phase::Walk;
    }
    // the nearest item heard that nobody holds (none taken in the nest: it is being delivered)
    const auto& heard = latestOf<RangeBearingMeasurement>(in.artifact, board_);
    const RangeBearingMeasurement::Message* nearest = nullptr;
    for (const auto& m : heard.messages) {
      if (m.data.empty() || m.data[0] != item_code_ || (nearest != nullptr && m.range >= nearest->range)) continue;
      if (env.artifact(m.sender).root().attachments() == 0) nearest = &m;
    }
    if (nearest == nullptr || in_nest) {
      // back to where the last item was found, then search about there
      if (has_site_ && std::hypot(site_x_ - odometry.x, site_y_ - odometry.y) < 0.1) has_site_ = false;
      if (!has_site_)
        diffuse(in);
      else if (!turnFromObstacle(in))
        steer(in, wrapAngle(std::atan2(site_y_ - odometry.y, site_x_ - odometry.x) - odometry.yaw));
      return;
    }
    if (nearest->range < grab_range_) {
      hand.attach(env.artifact(nearest->sender).root());
      site_x_ = odometry.x;
      site_y_ = odometry.y;
      has_site_ = true;
      carrying_ = static_cast<std::int64_t>(nearest->sender);
      until_ = t + 0.1;  // (the hold is made before the next step's physics)
      in.drive.setWheels(0, 0);
      return;
    }
    if (!turnFromObstacle(in)) steer(in, nearest->bearing);
  }
  void saveState(StateWriter& out) const override {
    Roaming::saveState(out);
    out.write(carrying_);
    out.write(home_x_);
    out.write(home_y_);
    out.write(has_home_);
    out.write(site_x_);
    out.write(site_y_);
    out.write(has_site_);
    out.write(lost_until_);
  }
  void loadState(StateReader& in) override {
    Roaming::loadState(in);
    carrying_ = in.get<std::int64_t>();
    in.read(home_x_);
    in.read(home_y_);
    in.read(has_home_);
    in.read(site_x_);
    in.read(site_y_);
    in.read(has_site_);
    in.read(lost_until_);
  }

 private:
  std::uint8_t item_code_;
  double grab_range_, nest_level_;
  std::int64_t carrying_ = -1;      // the item's artifact index, or -1
  double home_x_ = 0, home_y_ = 0;  // where odometry last had it in the nest
  bool has_home_ = false;
  double site_x_ = 0, site_y_ = 0;  // where odometry had it when it last took an item
  bool has_site_ = false;
  double lost_until_ = 0;  // carrying, it wanders until then (it did not find the nest where it thought)
};

// a constant twist from the start
class Twist final : public GroundController {
 public:
  explicit Twist(const Vec3& twist) : v_(twist.x()), w_(twist.y()) {}
  void step(double, GroundInputs& in) override { in.drive.setTwist(v_, w_); }

 private:
  double v_, w_;
};

}  // namespace

void validateBehaviour(const Descriptor& params, const Artifact& a) {
  const std::string controller = params.get<std::string>("controller");
  if (controller != "none" && controller != "twist" && sensorOf<ProximityMeasurement>(a) < 0)
    throw params.errorAt("controller", "the " + controller + " controller needs a proximity sensor on the artifact");
  if ((controller == "beeclust" || controller == "foraging") &&
      (sensorOf<RangeBearingMeasurement>(a) < 0 || sensorOf<GroundMeasurement>(a) < 0))
    throw params.errorAt("controller", "the " + controller +
                                           " controller needs a range_and_bearing and a ground sensor on the artifact");
}

std::unique_ptr<GroundController> makeBehaviour(const Descriptor& params, const Artifact& a, const DriveModel& drive) {
  const std::string controller = params.get<std::string>("controller");
  if (controller == "diffusion") return std::make_unique<Diffusion>(params, a, drive);
  if (controller == "beeclust") return std::make_unique<BeeClust>(params, a, drive);
  if (controller == "foraging") return std::make_unique<Foraging>(params, a, drive);
  if (controller == "twist") return std::make_unique<Twist>(params.get<Vec3>("twist"));
  return nullptr;
}

}  // namespace ssx::ground
