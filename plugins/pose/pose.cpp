// pose: ground-truth pose and twist of a node (ssx::PoseMeasurement), with optional Gaussian noise
// drawn from the sensor's own stream (so runs repeat on any number of threads), and optional
// latency: each measurement is the state `delay` (plus up to `delay_jitter`) ago, as an optical
// motion-capture system delivers it (about 6-7 ms for the capture alone; Crazyswarm, Preiss et al.,
// ICRA 2017), stamped with the time it was captured.
//
// Parameters: kParameters below, or `ssx plugins --params pose`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>
#include <ssx/state.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace ssx::plugins {

class PoseSensor final : public SensorOf<PoseMeasurement> {
 public:
  static constexpr const char* kDoc = "pose and twist of a node (a motion-capture stand-in), optionally noisy";
  static constexpr ssx_plugin_param kParameters[] = {
      param::text("node", "", "physic node to measure (default: the first root)"),
      param::real("position_noise", "0", "m", param::nonNegative(), "standard deviation per axis"),
      param::real("orientation_noise", "0", "rad", param::nonNegative(),
                  "standard deviation of a small rotation per axis"),
      param::real("velocity_noise", "0", "m/s", param::nonNegative(), "standard deviation per axis"),
      param::real("angular_velocity_noise", "0", "rad/s", param::nonNegative(), "standard deviation per axis"),
      param::real("delay", "0", "s", param::nonNegative() & param::atMost(1),
                  "latency: each measurement is the state this long ago (a whole number of sensor periods)"),
      param::real("delay_jitter", "0", "s", param::nonNegative() & param::atMost(1),
                  "extra latency, uniform in whole sensor periods from 0 to this; never older than the last"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    (void)context.artifact->nodeFromParameter(params);
    for (const char* key : {"delay", "delay_jitter"}) (void)periods(params, key, context.period());
  }

  void configure(const Descriptor& params, PluginSetup& /*setup*/) override {
    node_ = &artifact().nodeFromParameter(params);
    position_noise_ = params.get<double>("position_noise");
    orientation_noise_ = params.get<double>("orientation_noise");
    velocity_noise_ = params.get<double>("velocity_noise");
    angular_velocity_noise_ = params.get<double>("angular_velocity_noise");
    const Nanoseconds period = periodSteps() * artifact().environment().timestep();
    delay_ = periods(params, "delay", period);
    jitter_ = periods(params, "delay_jitter", period);
    history_.assign(static_cast<std::size_t>(delay_ + jitter_ + 1), {});
  }

  void saveState(StateWriter& out) const override {
    save(out, value());
    out.write(static_cast<std::uint64_t>(captured_));
    out.write(last_lag_);
    for (const Sample& h : history_) {
      out.write(h.stamp);
      out.write(h.pose);
      out.write(h.linear_velocity);
      out.write(h.angular_velocity);
    }
  }
  void loadState(StateReader& in) override {
    load(in, output());
    captured_ = static_cast<std::size_t>(in.get<std::uint64_t>());
    in.read(last_lag_);
    for (Sample& h : history_) {
      in.read(h.stamp);
      in.read(h.pose);
      in.read(h.linear_velocity);
      in.read(h.angular_velocity);
    }
  }

  void sense(const StepInfo& info) override {
    // the true state now goes into the history; the measurement is the one `lag` samples back
    // (the oldest there is, early on), never older than the one delivered last
    const BodyState now = node_->state();
    history_[captured_ % history_.size()] = {info.time, now.pose, now.linear_velocity, now.angular_velocity};
    ++captured_;
    std::int64_t lag = delay_;
    if (jitter_ > 0) lag += static_cast<std::int64_t>(random().uniform() * static_cast<double>(jitter_ + 1));
    lag = std::min({lag, last_lag_ + 1, static_cast<std::int64_t>(captured_) - 1});
    last_lag_ = lag;
    const Sample& s = history_[(captured_ - 1 - static_cast<std::size_t>(lag)) % history_.size()];
    PoseMeasurement& m = output();
    m.stamp = s.stamp;
    m.pose = s.pose;
    m.linear_velocity = s.linear_velocity;
    m.angular_velocity = s.angular_velocity;
    if (position_noise_ > 0) m.pose.position += noise(position_noise_);
    if (orientation_noise_ > 0) {
      const Vec3 r = noise(orientation_noise_);
      m.pose.orientation = (Quat(Eigen::AngleAxisd(r.norm(), r.normalized())) * m.pose.orientation).normalized();
    }
    if (velocity_noise_ > 0) m.linear_velocity += noise(velocity_noise_);
    if (angular_velocity_noise_ > 0) m.angular_velocity += noise(angular_velocity_noise_);
  }

 private:
  // three draws in a fixed order (the order of function arguments is unspecified in C++)
  Vec3 noise(double sigma) {
    Vec3 n;
    for (int i = 0; i < 3; ++i) n[i] = random().normal() * sigma;
    return n;
  }

  // a latency in whole sensor periods (ConfigError when it is not one)
  static std::int64_t periods(const Descriptor& params, const char* key, Nanoseconds period) {
    const double seconds = params.get<double>(key);
    const double n = seconds / toSeconds(period);
    if (std::abs(n - std::round(n)) > 1e-6)
      throw params.errorAt(key, "parameter '" + std::string(key) + "' = " + params.get<std::string>(key) +
                                    " s must be a whole number of the sensor's periods (" +
                                    std::to_string(toSeconds(period) * 1e3) + " ms)");
    return std::llround(n);
  }

  struct Sample {
    Nanoseconds stamp = 0;
    Pose pose;
    Vec3 linear_velocity = Vec3::Zero(), angular_velocity = Vec3::Zero();
  };
  std::vector<Sample> history_;  // a ring of the last delay + jitter + 1 true states
  std::size_t captured_ = 0;
  std::int64_t delay_ = 0, jitter_ = 0, last_lag_ = 0;
  const PhysicNode* node_ = nullptr;
  double position_noise_ = 0, orientation_noise_ = 0, velocity_noise_ = 0, angular_velocity_noise_ = 0;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::PoseSensor, "pose"));
