// ros1: a SimulationExtension that bridges robots to ROS 1, so that real control programs talk to
// simulated robots (the paper's main use of extensions).
//
// Per robot (its artifact name is the namespace): /<name>/odom (nav_msgs/Odometry, world frame
// pose, body-frame twist), /<name>/imu (sensor_msgs/Imu) when it has an IMU sensor, and a
// subscription to /<name>/setpoint (geometry_msgs/PoseStamped) that feeds its driver's external
// set-point (drivers implementing ssx::SetpointInterface, such as the quadrotor); /clock carries
// simulated time. Stamps are simulated time.
//
// The node is started in init (no SIGINT handler of its own: the host keeps Ctrl-C) with an
// asynchronous spinner; set-points are applied in beforeStep, on the stepping thread. Messages are
// serialised and published on a thread of the bridge's own: a step only copies their numbers. With
// lockstep="true", after each odometry message the simulation waits (at most lockstep_timeout_s)
// until every robot has a set-point stamped at or after that odometry's time, so a controller
// outside sees the same timing in real time and in faster runs.
//
// Parameters: kParameters below, or `ssx plugins --params ros1`.
#include "ros_bridge.hpp"

#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>
#include <ssx/setpoint.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace ssx::plugins {

namespace {

// a rate in simulated time: due at 0, period, 2 period, ...
struct Rate {
  Nanoseconds period = 0;  // 0: never
  Nanoseconds next = 0;
  bool due(Nanoseconds now) {
    if (period <= 0 || now < next) return false;
    next += period;
    if (next <= now) next = now + period;
    return true;
  }
};

Rate rateOf(const Descriptor& params, const char* key, Nanoseconds every_step) {
  const double hz = params.get<double>(key);
  Rate r;
  r.period = hz > 0 ? toNanoseconds(1.0 / hz) : every_step;
  return r;
}

std::array<double, 3> array3(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
std::array<double, 4> array4(const Quat& q) { return {q.w(), q.x(), q.y(), q.z()}; }

}  // namespace

class Ros1Bridge final : public SimulationExtension {
 public:
  static constexpr const char* kDoc = "bridges robots to ROS 1: odometry, IMU and /clock out, set-points in";
  static constexpr ssx_plugin_param kParameters[] = {
      param::text("master_uri", "", "ROS master (default: $ROS_MASTER_URI, else http://127.0.0.1:11311)"),
      param::text("node_name", "ssx", "name of the ROS node"),
      param::real("timeout_s", "5", "s", param::positive() & param::atMost(86400), "how long to wait for the master at start"),
      param::text("artifacts", "*", "artifact names separated by spaces, or * for every artifact with a dynamic root"),
      param::real("odom_rate_hz", "50", "Hz", param::nonNegative(), "odometry rate in simulated time; 0: every step"),
      param::real("imu_rate_hz", "100", "Hz", param::nonNegative(), "IMU rate in simulated time; 0: no IMU topics"),
      param::real("clock_rate_hz", "100", "Hz", param::nonNegative(), "/clock rate in simulated time; 0: every step"),
      param::flag("lockstep", "false", "wait after each odometry message until every robot answered with a set-point"),
      param::real("lockstep_timeout_s", "2", "s", param::positive() & param::atMost(86400), "longest wait for the set-points of one step"),
      param::real("lockstep_connect_timeout_s", "10", "s", param::positive() & param::atMost(86400),
                  "how long the first step waits for every robot's controller to connect"),
  };

  // what is bridged exists before the node is started
  static void validate(const Descriptor& params, const PluginContext& context) {
    (void)context.environment->selectArtifacts(params, "artifacts", "bridge");
  }

  void init(Environment& env, const Descriptor& params) override {
    publish_costs_.reserve(1 << 16);
    const char* env_uri = std::getenv("ROS_MASTER_URI");
    const std::string master =
        params.get<std::string>("master_uri", env_uri != nullptr ? env_uri : "http://127.0.0.1:11311");
    const std::string node = params.get<std::string>("node_name");
    const double timeout = params.get<double>("timeout_s");
    odom_rate_ = rateOf(params, "odom_rate_hz", env.timestep());
    imu_rate_ = rateOf(params, "imu_rate_hz", env.timestep());
    if (params.get<double>("imu_rate_hz") == 0) imu_rate_.period = 0;
    clock_rate_ = rateOf(params, "clock_rate_hz", env.timestep());
    lockstep_ = params.get<bool>("lockstep");
    lockstep_timeout_ = params.get<double>("lockstep_timeout_s");
    connect_timeout_ = params.get<double>("lockstep_connect_timeout_s");
    const std::vector<Artifact*> chosen = env.selectArtifacts(params, "artifacts", "bridge");
    std::vector<ros1::RobotTopics> topics;
    for (Artifact* a : chosen) {
      Robot r;
      r.artifact = a;
      r.tracker = dynamic_cast<SetpointInterface*>(a->driver());
      for (std::size_t k = 0; k < a->sensorCount(); ++k)
        if (r.imu == nullptr) r.imu = dynamic_cast<const ImuMeasurement*>(&a->sensor(k).latest());
      topics.push_back({a->name(), r.imu != nullptr && imu_rate_.period > 0, r.tracker != nullptr});
      robots_.push_back(r);
    }
    try {
      bridge_ = std::make_unique<ros1::Bridge>(master, node, timeout, topics);
    } catch (const std::exception& e) {
      throw params.error(e.what());
    }
  }

  void beforeStep(Environment& env) override {
    if (lockstep_ && !connected_) {
      // before the first step: the controllers must be connected, or the first odometry is lost
      const auto missing = bridge_->waitForPeers(connect_timeout_);
      if (!missing.empty())
        throw Error("lock-step: no controller connected within " + std::to_string(connect_timeout_) +
                    " s (subscribed to /<robot>/odom and publishing /<robot>/setpoint) for " +
                    std::to_string(missing.size()) + " robot(s), first '" + missing.front() + "'");
      connected_ = true;
    }
    if (lockstep_ && waiting_for_ >= 0) {
      const auto missing = bridge_->waitForSetpoints(waiting_for_, lockstep_timeout_);
      if (!missing.empty()) {
        std::string names;
        for (std::size_t i = 0; i < missing.size() && i < 5; ++i) names += (i ? ", " : "") + missing[i];
        if (missing.size() > 5) names += ", ...";
        throw Error("lock-step: no set-point stamped at or after t = " + std::to_string(waiting_for_) + " s within " +
                    std::to_string(lockstep_timeout_) + " s from " + std::to_string(missing.size()) +
                    " robot(s): " + names);
      }
      waiting_for_ = -1;
    }
    // the newest set-point of each robot, applied between steps
    for (std::size_t i = 0; i < robots_.size(); ++i) {
      Robot& r = robots_[i];
      if (r.tracker == nullptr) continue;
      const ros1::Setpoint s = bridge_->latestSetpoint(i);
      if (s.count == r.applied) continue;
      r.applied = s.count;
      Setpoint sp;
      sp.position = Vec3(s.position[0], s.position[1], s.position[2]);
      const Quat q(s.orientation[0], s.orientation[1], s.orientation[2], s.orientation[3]);
      sp.yaw = std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()));
      if (!sp.position.allFinite() || !std::isfinite(sp.yaw))
        throw Error("set-point for '" + r.artifact->name() + "' is not finite");
      r.tracker->setSetpoint(sp);
    }
    (void)env;
  }

  void afterStep(Environment& env) override {
    const auto started = std::chrono::steady_clock::now();
    const Nanoseconds now = env.time();
    const double t = toSeconds(now);
    // (due() moves a rate on to its next time: asked once per step)
    const bool clock_due = clock_rate_.due(now), imu_due = imu_rate_.due(now), odom_due = odom_rate_.due(now);
    const bool publishing = clock_due || imu_due || odom_due;
    if (clock_due) bridge_->publishClock(t);
    if (imu_due) {
      for (std::size_t i = 0; i < robots_.size(); ++i) {
        const Robot& r = robots_[i];
        if (r.imu == nullptr) continue;
        ros1::Imu m;
        m.time = t;
        m.angular_velocity = array3(r.imu->gyroscope);
        m.linear_acceleration = array3(r.imu->accelerometer);
        m.orientation = array4(r.artifact->root().pose().orientation);
        bridge_->publishImu(i, m);
      }
    }
    if (odom_due) {
      for (std::size_t i = 0; i < robots_.size(); ++i) {
        const BodyState s = robots_[i].artifact->root().state();
        const Quat to_body = s.pose.orientation.conjugate();
        ros1::Odometry m;
        m.time = t;
        m.position = array3(s.pose.position);
        m.orientation = array4(s.pose.orientation);
        m.velocity = array3(to_body * s.linear_velocity);
        m.angular_velocity = array3(to_body * s.angular_velocity);
        bridge_->publishOdometry(i, m);
      }
      if (lockstep_) waiting_for_ = t;
    }
    bridge_->commit();  // serialised and sent on the bridge's own thread
    // what publishing costs the stepping thread, for the log (the first 2^16 publishing steps)
    if (publishing && publish_costs_.size() < publish_costs_.capacity())
      publish_costs_.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  }

  void shutdown(Environment& env) override {
    if (bridge_) {
      // how quickly the controllers outside answered, as one line in the log
      std::vector<double> rt = bridge_->roundTrips();
      if (!rt.empty()) {
        std::sort(rt.begin(), rt.end());
        char line[200];
        std::snprintf(line, sizeof line,
                      "ros1: %zu set-points answered odometry; round trip median %.2f ms, p99 %.2f ms, max %.2f ms",
                      rt.size(), 1e3 * rt[rt.size() / 2], 1e3 * rt[rt.size() * 99 / 100], 1e3 * rt.back());
        env.log(LogLevel::Info, line);
      }
      if (!publish_costs_.empty()) {
        std::vector<double> c = publish_costs_;
        std::sort(c.begin(), c.end());
        char line[200];
        std::snprintf(line, sizeof line,
                      "ros1: publishing took the stepping thread median %.1f us, p99 %.1f us, max %.1f us per "
                      "publishing step (%zu steps)",
                      1e6 * c[c.size() / 2], 1e6 * c[c.size() * 99 / 100], 1e6 * c.back(), c.size());
        env.log(LogLevel::Info, line);
      }
      bridge_->shutdown();
    }
    bridge_.reset();
  }

 private:
  struct Robot {
    Artifact* artifact = nullptr;
    SetpointInterface* tracker = nullptr;
    const ImuMeasurement* imu = nullptr;
    std::uint64_t applied = 0;  // set-points applied so far
  };
  std::unique_ptr<ros1::Bridge> bridge_;
  std::vector<Robot> robots_;
  Rate odom_rate_, imu_rate_, clock_rate_;
  bool lockstep_ = false;
  double lockstep_timeout_ = 2.0, connect_timeout_ = 10.0;
  bool connected_ = false;
  double waiting_for_ = -1;  // lock-step: the odometry time set-points must answer
  std::vector<double> publish_costs_;  // s, per publishing step (reserved at init)
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_EXTENSION(ssx::plugins::Ros1Bridge, "ros1"));
