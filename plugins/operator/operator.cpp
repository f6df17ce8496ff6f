// operator: a person steering robots by velocity and feeling the world they steer them through
// (ssx::OperatorInterface; the bridges take /<name>/cmd_vel and /<name>/joy and send /<name>/force).
//
// Commands: every steered robot gets the same velocity command (a formation moves as one), in the
// world frame or in the heading of the first steered robot (frame="body"), clipped to max_speed
// and max_yaw_rate. The dead-man rule: with no command for deadman_s of simulated time, or with a
// joystick's dead-man button released, every steered robot is commanded to stop (velocity 0).
//
// Force feedback, the law: for each steered robot at p, each obstacle surface point q and each robot
// not steered (ghosts included) at q within force_range R of it, at distance d, adds
// force_gain * (1 - d / R) * (p - q) / d; the sum is saturated at force_max (N, world frame). It
// points away from what is near and grows linearly as it gets nearer; the steered robots' own
// pushes on each other cancel in a sum, so they are left out.
//
// Parameters: kParameters below, or `ssx plugins --params operator`.
#include <ssx/artifact.hpp>
#include <ssx/command.hpp>
#include <ssx/environment.hpp>
#include <ssx/operator.hpp>
#include <ssx/plugin_abi.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace ssx::plugins {

namespace {

// "1 0 -1 3": joystick axes for vx, vy, vz and the yaw rate (-1: none); empty when malformed
std::vector<int> axesOf(const std::string& text) {
  std::istringstream in(text);
  std::vector<int> out;
  for (int v; in >> v;) out.push_back(v);
  if (!in.eof() || out.size() != 4) return {};
  for (int v : out)
    if (v < -1 || v > 63) return {};
  return out;
}

}  // namespace

class Operator final : public SimulationExtension, public OperatorInterface {
 public:
  static constexpr const char* kDoc = "a person steering robots by velocity, with a dead-man rule and force feedback";
  static constexpr ssx_plugin_param kParameters[] = {
      param::required(param::text("robots", "", "the robots steered as one: names separated by spaces, or * for every robot")),
      param::choice("frame", "world", "world body", "commands in the world frame, or in the first steered robot's heading"),
      param::real("max_speed", "1", "m/s", param::positive(), "commands are clipped to this speed"),
      param::real("max_yaw_rate", "1", "rad/s", param::positive(), "and to this yaw rate"),
      param::real("deadman_s", "0.5", "s", param::positive(), "with no command this long (simulated time), the robots stop"),
      param::text("joy_axes", "1 0 -1 3", "joystick axes for vx, vy, vz and the yaw rate, scaled by the limits (-1: none)"),
      param::integer("joy_deadman_button", "-1", param::atLeast(-1),
                     "a joystick button that must be held for the robots to move (-1: none)"),
      param::real("force_range", "1.5", "m", param::positive(), "obstacles and robots nearer push back"),
      param::real("force_gain", "2", "N", param::nonNegative(), "the push of one at zero distance"),
      param::real("force_max", "5", "N", param::positive(), "the force's largest magnitude"),
      param::real("force_rate_hz", "100", "Hz", param::nonNegative() & param::atMost(1e9),
                  "how often the bridges send it; 0: every step"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    for (const Artifact* a : context.environment->selectArtifacts(params, "robots", "steer")) {
      const auto* driver = dynamic_cast<const CommandInterface*>(a->driver());
      if (driver == nullptr || !driver->acceptsCommand(CommandLevel::Velocity))
        throw params.error("'" + a->name() + "' cannot be steered: its driver takes no velocity commands");
    }
    if (axesOf(params.get<std::string>("joy_axes")).empty())
      throw params.error("joy_axes must be four axis numbers (0-63, or -1 for none), got '" +
                         params.get<std::string>("joy_axes") + "'");
  }

  void init(Environment& env, const Descriptor& params) override {
    env_ = &env;
    for (Artifact* a : env.selectArtifacts(params, "robots", "steer")) {
      robots_.push_back(a);
      drivers_.push_back(dynamic_cast<CommandInterface*>(a->driver()));
    }
    body_frame_ = params.get<std::string>("frame") == "body";
    max_speed_ = params.get<double>("max_speed");
    max_yaw_rate_ = params.get<double>("max_yaw_rate");
    deadman_ = toNanoseconds(params.get<double>("deadman_s"));
    axes_ = axesOf(params.get<std::string>("joy_axes"));
    deadman_button_ = static_cast<int>(params.get<std::int64_t>("joy_deadman_button"));
    range_ = params.get<double>("force_range");
    gain_ = params.get<double>("force_gain");
    max_force_ = params.get<double>("force_max");
    force_rate_ = params.get<double>("force_rate_hz");
    env.enableNeighborQueries(range_);
  }

  // the dead-man rule, before each step's physics
  void beforeStep(Environment& env) override {
    if (moving_ && env.time() - last_command_ > deadman_) stop();
  }

  void shutdown(Environment& env) override {
    if (commands_ > 0 || stops_ > 0)
      env.log(LogLevel::Info, "operator: " + std::to_string(commands_) + " commands, " + std::to_string(stops_) +
                                  " stops by the dead-man rule");
  }

  void saveState(StateWriter& out) const override {
    out.write(last_command_);
    out.write(static_cast<std::uint8_t>(moving_ ? 1 : 0));
  }
  void loadState(StateReader& in) override {
    const auto last = in.get<Nanoseconds>();
    const auto moving = in.get<std::uint8_t>();
    if (moving > 1) throw StateError("operator: a moving flag that is neither 0 nor 1 (corrupted)");
    last_command_ = last;
    moving_ = moving == 1;
  }

  void command(const Vec3& velocity, double yaw_rate) override {
    if (env_ == nullptr) throw Error("operator: the run has not started: commands are taken from the first step on");
    if (!velocity.allFinite() || !std::isfinite(yaw_rate)) throw Error("operator: a command that is not finite");
    Vec3 v = velocity;
    if (v.norm() > max_speed_) v *= max_speed_ / v.norm();
    const double w = std::clamp(yaw_rate, -max_yaw_rate_, max_yaw_rate_);
    if (body_frame_) {
      const Quat q = robots_.front()->root().pose().orientation;
      const double yaw = std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()));
      v = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ())) * v;
    }
    const Command c = Command::velocityYawRate(v, w);
    for (CommandInterface* d : drivers_) d->setCommand(c);
    last_command_ = env_->time();
    moving_ = true;
    ++commands_;
  }

  void joy(std::span<const float> axes, std::span<const int> buttons) override {
    if (env_ == nullptr) throw Error("operator: the run has not started: commands are taken from the first step on");
    if (deadman_button_ >= 0 &&
        (static_cast<std::size_t>(deadman_button_) >= buttons.size() || buttons[static_cast<std::size_t>(deadman_button_)] == 0)) {
      if (moving_) stop();
      return;
    }
    auto axis = [&](int k) { return k >= 0 && static_cast<std::size_t>(k) < axes.size() ? double(axes[static_cast<std::size_t>(k)]) : 0.0; };
    command(max_speed_ * Vec3(axis(axes_[0]), axis(axes_[1]), axis(axes_[2])), max_yaw_rate_ * axis(axes_[3]));
  }

  Vec3 force() const override {
    Vec3 f = Vec3::Zero();
    if (env_ == nullptr) return f;
    auto push = [&](const Vec3& p, const Vec3& q) {
      const Vec3 away = p - q;
      const double d = away.norm();
      if (d < range_ && d > 1e-9) f += gain_ * (1 - d / range_) * away / d;
    };
    for (const Artifact* a : robots_) {
      const Vec3 p = a->root().pose().position;
      for (const Environment::StaticShape& o : env_->staticShapes())
        if (o.shape.kind != Shape::Kind::Plane) push(p, nearestSurfacePoint(o.shape, o.world, p));
      env_->forEachNeighbor(p, range_, [&](std::size_t j, const Vec3& q) {
        if (!isSteered(j)) push(p, q);
      });
    }
    if (f.norm() > max_force_) f *= max_force_ / f.norm();
    return f;
  }
  double forceRateHz() const override { return force_rate_; }
  const std::vector<Artifact*>& steered() const override { return robots_; }

 private:
  void stop() {
    for (CommandInterface* d : drivers_) d->setCommand(Command::velocityYawRate(Vec3::Zero(), 0));
    moving_ = false;
    ++stops_;
  }
  bool isSteered(std::size_t artifact) const {
    return std::any_of(robots_.begin(), robots_.end(), [&](const Artifact* a) { return a->index() == artifact; });
  }

  Environment* env_ = nullptr;
  std::vector<Artifact*> robots_;
  std::vector<CommandInterface*> drivers_;
  bool body_frame_ = false;
  double max_speed_ = 1, max_yaw_rate_ = 1;
  Nanoseconds deadman_ = 500'000'000;
  std::vector<int> axes_;
  int deadman_button_ = -1;
  double range_ = 1.5, gain_ = 2, max_force_ = 5, force_rate_ = 100;
  Nanoseconds last_command_ = 0;
  bool moving_ = false;
  std::uint64_t commands_ = 0, stops_ = 0;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_EXTENSION(ssx::plugins::Operator, "operator"));
