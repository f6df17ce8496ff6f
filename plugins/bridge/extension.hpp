#pragma once
// What the ROS bridges share above their transport: which robots are bridged, what is published
// when (rates in simulated time), applying what arrived between steps (set-points, velocity
// commands), lock-step with the controllers outside, and the log lines at the end. A bridge is this
// class with a transport (open()); ros1 and ros2 differ only there.
#include "commands.hpp"
#include "frames.hpp"
#include "transport.hpp"

#include <ssx/command.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/operator.hpp>
#include <ssx/plugin_abi.hpp>
#include <ssx/setpoint.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <sstream>
#include <string>
#include <vector>

namespace ssx::bridge {

/// Rates up to 1e9 Hz (every step of any timestep; the parameters' own check refuses a rate in
/// (0, 1e-6) Hz).
inline constexpr double kMaxRateHz = 1e9;

/// The parameters both bridges take, with the same meaning (the part "bridge" of their tables).
inline constexpr ssx_plugin_param kBridgeParameters[] = {
    param::text("artifacts", "*", "artifact names separated by spaces, or * for every artifact with a dynamic root"),
    param::real("odom_rate_hz", "50", "Hz", param::nonNegative() & param::atMost(kMaxRateHz), "odometry rate in simulated time; 0: every step"),
    param::real("imu_rate_hz", "100", "Hz", param::nonNegative() & param::atMost(kMaxRateHz), "IMU rate in simulated time; 0: no IMU topics"),
    param::real("clock_rate_hz", "100", "Hz", param::nonNegative() & param::atMost(kMaxRateHz), "/clock rate in simulated time; 0: every step"),
    param::flag("lockstep", "false", "wait after each odometry message until every robot answered with a set-point"),
    param::real("lockstep_timeout_s", "2", "s", param::positive() & param::atMost(86400), "longest wait for the set-points of one step"),
    param::real("lockstep_connect_timeout_s", "10", "s", param::positive() & param::atMost(86400),
                "how long the first step waits for every robot's controller to connect, and for their first answers"),
    param::real("range_rate_hz", "10", "Hz", param::nonNegative() & param::atMost(kMaxRateHz),
                "rate of /<robot>/range (what a range sensor sees, as a PoseArray) in simulated time; 0: none"),
    param::real("image_rate_hz", "10", "Hz", param::nonNegative() & param::atMost(kMaxRateHz),
                "rate of /<robot>/image (what a camera sensor sees, rgb8) in simulated time; 0: none"),
    param::real("scan_rate_hz", "10", "Hz", param::nonNegative() & param::atMost(kMaxRateHz),
                "rate of /<robot>/scan (its proximity ring as a LaserScan; ROS 2) in simulated time; 0: none"),
    param::real("ground_rate_hz", "10", "Hz", param::nonNegative() & param::atMost(kMaxRateHz),
                "rate of /<robot>/ground (ssx_msgs/Ground; ROS 2) in simulated time; 0: none"),
    param::real("range_bearing_rate_hz", "10", "Hz", param::nonNegative() & param::atMost(kMaxRateHz),
                "rate of /<robot>/range_bearing (ssx_msgs/RangeBearing: the messages received since; ROS 2) in simulated time; 0: none"),
    param::text("operators", "", "operator extensions bridged: names separated by spaces (/<name>/cmd_vel and "
                "/<name>/joy in, /<name>/force out)"),
    param::choice("pose_stamps", "sim", "sim wall",
                  "a ghost's /<robot>/pose stamps are simulated time (sim: a peer on /clock) or the system clock "
                  "(wall: a motion-capture driver's); a zero stamp is the time it arrived"),
};

class BridgeExtension : public SimulationExtension {
 public:
  // what is bridged exists before the transport is started
  static void validate(const Descriptor& params, const PluginContext& context) {
    (void)context.environment->selectArtifacts(params, "artifacts", "bridge");
    (void)operatorsOf(params, *context.environment);
    if (params.get<bool>("lockstep") && params.get<std::string>("pose_stamps") == "wall")
      throw params.error("pose_stamps=\"wall\" cannot be lock-stepped (the wall clock is not the same twice): use "
                         "pose_stamps=\"sim\" with lockstep=\"true\"");
  }

  void init(Environment& env, const Descriptor& params) override {
    publish_costs_.reserve(1 << 16);
    odom_rate_ = rateOf(params, "odom_rate_hz", env.timestep());
    imu_rate_ = rateOf(params, "imu_rate_hz", env.timestep());
    if (params.get<double>("imu_rate_hz") == 0) imu_rate_.period = 0;
    clock_rate_ = rateOf(params, "clock_rate_hz", env.timestep());
    lockstep_ = params.get<bool>("lockstep");
    lockstep_timeout_ = params.get<double>("lockstep_timeout_s");
    connect_timeout_ = params.get<double>("lockstep_connect_timeout_s");
    range_rate_ = rateOf(params, "range_rate_hz", env.timestep());
    if (params.get<double>("range_rate_hz") == 0) range_rate_.period = 0;
    ground_rate_ = rateOf(params, "ground_rate_hz", env.timestep());
    if (params.get<double>("ground_rate_hz") == 0) ground_rate_.period = 0;
    rab_rate_ = rateOf(params, "range_bearing_rate_hz", env.timestep());
    if (params.get<double>("range_bearing_rate_hz") == 0) rab_rate_.period = 0;
    scan_rate_ = rateOf(params, "scan_rate_hz", env.timestep());
    if (params.get<double>("scan_rate_hz") == 0) scan_rate_.period = 0;
    image_rate_ = rateOf(params, "image_rate_hz", env.timestep());
    if (params.get<double>("image_rate_hz") == 0) image_rate_.period = 0;
    wall_stamps_ = params.get<std::string>("pose_stamps") == "wall";  // (not with lockstep: validate)
    std::vector<RobotTopics> topics;
    for (Artifact* a : env.selectArtifacts(params, "artifacts", "bridge")) {
      Robot r;
      r.artifact = a;
      r.tracker = dynamic_cast<SetpointInterface*>(a->driver());
      r.commands = dynamic_cast<CommandInterface*>(a->driver());
      if (r.commands != nullptr && !r.commands->acceptsCommand(CommandLevel::Velocity)) r.commands = nullptr;
      std::size_t imu_k = a->sensorCount(), ring_k = imu_k, camera_k = imu_k;  // (which sensors they are)
      for (std::size_t k = 0; k < a->sensorCount(); ++k) {
        if (r.imu == nullptr && (r.imu = dynamic_cast<const ImuMeasurement*>(&a->sensor(k).latest()))) imu_k = k;
        if (r.range == nullptr) r.range = dynamic_cast<const RangeMeasurement*>(&a->sensor(k).latest());
        if (r.camera == nullptr && (r.camera = dynamic_cast<const CameraMeasurement*>(&a->sensor(k).latest())))
          camera_k = k;
        if (r.proximity == nullptr && (r.proximity = dynamic_cast<const ProximityMeasurement*>(&a->sensor(k).latest())))
          ring_k = k;
        if (r.ground == nullptr) r.ground = dynamic_cast<const GroundMeasurement*>(&a->sensor(k).latest());
        if (r.rab == nullptr) r.rab = dynamic_cast<const RangeBearingMeasurement*>(&a->sensor(k).latest());
      }
      RobotTopics t;
      t.name = a->name();
      t.imu = r.imu != nullptr && imu_rate_.period > 0;
      t.setpoint = r.tracker != nullptr;
      t.velocity = r.commands != nullptr;
      t.ghost = env.isGhost(*a);
      t.range = r.range != nullptr && range_rate_.period > 0;
      t.image = r.camera != nullptr && image_rate_.period > 0;
      // its other bodies on /tf, its hinges and sliders on joint_states, its fixed frames on
      // /tf_static and its description, where the transport offers them
      t.tf = offersTransforms();
      if (t.tf) {
        frames(*a, r.parts, r.joints, t);
        t.root_frame = linkName(*a, a->root());
        t.description = describe(*a);
        t.joint_commands = !t.joints.empty();
        if (r.proximity != nullptr && scan_rate_.period > 0) scanOf(t);
        sensorFrames(*a, t.imu ? imu_k : a->sensorCount(), ring_k, camera_k, t);
        t.ground = r.ground != nullptr && ground_rate_.period > 0;
        t.range_bearing = r.rab != nullptr && rab_rate_.period > 0;
      }
      topics.push_back(t);
      robots_.push_back(r);
    }
    // operators after the robots, their topics under their own names
    for (const auto& [n, op] : operatorsOf(params, env)) {
      Operator o;
      o.op = op;  // (its force rate is read at the first step: it may be initialised after this one)
      o.name = n;
      operators_.push_back(o);
      RobotTopics t;
      t.name = n;
      t.velocity = true;
      t.odom = false;
      t.joy = true;
      t.force = true;
      topics.push_back(t);
    }
    try {
      transport_ = open(env, params, topics);
    } catch (const std::exception& e) {
      throw params.error(e.what());
    }
  }

  void beforeStep(Environment& env) override {
    // (a Ctrl-C while waiting ends the wait; the run ends after this step)
    const auto stop = [&env] { return env.stopRequested(); };
    if (lockstep_ && !connected_) {
      // before the first step: the controllers must be connected, or the first odometry is lost
      const auto missing = transport_->waitForPeers(connect_timeout_, stop);
      if (!missing.empty() && env.stopRequested()) return;
      if (!missing.empty())
        throw Error("lock-step: no controller connected within " + std::to_string(connect_timeout_) +
                    " s (subscribed to /<robot>/odom and publishing /<robot>/setpoint) for " +
                    std::to_string(missing.size()) + " robot(s), first '" + missing.front() + "'");
      connected_ = true;
    }
    if (lockstep_ && waiting_for_ >= 0) {
      // the first answers may take as long as connecting: a controller that has just connected may
      // not have heard the first odometry yet (and one matched may be a peer that just left, whose
      // endpoints DDS still lists until their lease runs out)
      const double wait = answered_ ? lockstep_timeout_ : std::max(lockstep_timeout_, connect_timeout_);
      const auto missing = transport_->waitForSetpoints(waiting_for_, wait, stop);
      if (!missing.empty() && env.stopRequested()) return;
      if (!missing.empty()) {
        std::string names;
        for (std::size_t i = 0; i < missing.size() && i < 5; ++i) names += (i ? ", " : "") + missing[i];
        if (missing.size() > 5) names += ", ...";
        throw Error("lock-step: no set-point stamped at or after t = " + std::to_string(waiting_for_) + " s within " +
                    std::to_string(wait) + " s from " + std::to_string(missing.size()) + " robot(s): " + names);
      }
      answered_ = true;
      cutoff_ = waiting_for_;
      waiting_for_ = -1;
    }
    // each robot's newest set-point and velocity command, applied between steps in the order they
    // arrived, and every pose of a ghost (most steps nothing did: then no robot is looked up)
    const std::uint64_t received = transport_->received();
    if (received == received_seen_ && !(lockstep_ && !operators_.empty())) {
      if (!held_.empty()) applyPoses(env);
      return;
    }
    received_seen_ = received;
    for (std::size_t k = 0; k < operators_.size(); ++k) {
      // each operator's newest command and joystick state, in the order they arrived
      Operator& o = operators_[k];
      const std::size_t i = robots_.size() + k;
      const Velocity v = transport_->latestVelocity(i);
      const Joy j = transport_->latestJoy(i);
      const bool new_velocity = v.count != o.velocities;
      // (lock-stepped, a joystick state is used once the odometry it answers is: the same step in
      // every run; a newer one that came meanwhile replaces it)
      const bool new_joy = j.count != o.joys && (!lockstep_ || j.stamp <= cutoff_ + 1e-9);
      o.velocities = v.count;
      if (new_joy) o.joys = j.count;
      // (a command the operator refuses, not finite or absurd, is dropped and counted: one bad
      // message never stops the run)
      auto velocity = [&] {
        guarded(env, o.name, "cmd_vel", [&] { o.op->command(Vec3(v.linear[0], v.linear[1], v.linear[2]), v.angular[2]); });
      };
      auto joy = [&] { guarded(env, o.name, "joy", [&] { o.op->joy(j.axes, j.buttons); }); };
      if (new_velocity && new_joy && j.order < v.order) joy();
      if (new_velocity) velocity();
      if (new_joy && !(new_velocity && j.order < v.order)) joy();
    }
    transport_->takePoses(arrived_);
    // a peer sending poses stamped far ahead (held until due when lock-stepped) cannot make them
    // pile up: beyond what the transport would queue for every robot, the last to arrive (the
    // furthest ahead) are dropped, counted with the transport's
    const std::size_t most = Transport::kMaxPosesQueued * robots_.size();
    const std::size_t take = std::min(arrived_.size(), most > held_.size() ? most - held_.size() : 0);
    held_dropped_ += arrived_.size() - take;
    held_.insert(held_.end(), arrived_.begin(), arrived_.begin() + static_cast<std::ptrdiff_t>(take));
    if (!held_.empty()) applyPoses(env);
    for (std::size_t i = 0; i < robots_.size(); ++i) {
      Robot& r = robots_[i];
      const Setpoint s = r.tracker != nullptr ? transport_->latestSetpoint(i) : Setpoint{};
      const Velocity v = r.commands != nullptr ? transport_->latestVelocity(i) : Velocity{};
      const bool new_setpoint = s.count != r.setpoints, new_velocity = v.count != r.velocities;
      r.setpoints = s.count;
      r.velocities = v.count;
      const std::string& who = r.artifact->name();
      auto setpoint = [&] { guarded(env, who, "setpoint", [&] { applySetpoint(*r.tracker, s); }); };
      auto velocity = [&] { guarded(env, who, "cmd_vel", [&] { applyVelocity(*r.artifact, *r.commands, v); }); };
      if (new_velocity && new_setpoint && v.order < s.order) velocity();
      if (new_setpoint) setpoint();
      if (new_velocity && !(new_setpoint && v.order < s.order)) velocity();
      if (r.joints.empty()) continue;
      // its newest joint command (the transport's only if it offers them)
      const JointCommand j = transport_->latestJointCommand(i);
      if (j.count == r.joint_commands) continue;
      r.joint_commands = j.count;
      guarded(env, who, "joint_command", [&] { applyJoints(*r.artifact, r.joints, j); });
    }
  }

  void afterStep(Environment& env) override {
    const auto started = std::chrono::steady_clock::now();
    const Nanoseconds now = env.time();
    const double t = toSeconds(now);
    // (due() moves a rate on to its next time: asked once per step)
    const bool clock_due = clock_rate_.due(now), imu_due = imu_rate_.due(now), odom_due = odom_rate_.due(now);
    if (clock_due) transport_->publishClock(t);
    if (imu_due) {
      for (std::size_t i = 0; i < robots_.size(); ++i) {
        const Robot& r = robots_[i];
        if (r.imu == nullptr) continue;
        Imu m;
        m.time = t;
        m.angular_velocity = array3(r.imu->gyroscope);
        m.linear_acceleration = array3(r.imu->accelerometer);
        m.orientation = array4(r.artifact->root().pose().orientation);
        transport_->publishImu(i, m);
      }
    }
    if (odom_due) {
      for (std::size_t i = 0; i < robots_.size(); ++i) {
        const BodyState s = robots_[i].artifact->root().state();
        const Quat to_body = s.pose.orientation.conjugate();
        Odometry m;
        m.time = t;
        m.position = array3(s.pose.position);
        m.orientation = array4(s.pose.orientation);
        m.velocity = array3(to_body * s.linear_velocity);
        m.angular_velocity = array3(to_body * s.angular_velocity);
        transport_->publishOdometry(i, m);
        if (!transport_->robots()[i].tf) continue;
        // its frames at the odometry's time: base_link (the odometry's pose) and each part
        values_.clear();
        appendPose(values_, s.pose);
        for (const PhysicNode* part : robots_[i].parts) appendPose(values_, part->pose());
        transport_->publishTransforms(i, t, values_);
        if (robots_[i].joints.empty()) continue;
        values_.clear();
        for (const PhysicNode* joint : robots_[i].joints) {
          values_.push_back(joint->jointPosition());
          values_.push_back(joint->jointVelocity());
        }
        transport_->publishJointStates(i, t, values_);
      }
      if (lockstep_) waiting_for_ = t;
    }
    if (range_rate_.due(now)) {
      for (std::size_t i = 0; i < robots_.size(); ++i) {
        Robot& r = robots_[i];
        // (a sensor that did not measure since, a lost ghost's, publishes nothing new)
        if (r.range == nullptr || r.range->stamp == r.range_published) continue;
        r.range_published = r.range->stamp;
        points_.clear();
        for (const auto& d : r.range->detections) points_.push_back(array3(d.relative));
        transport_->publishRange(i, toSeconds(r.range->stamp), r.range->body_frame, points_);
      }
    }
    const bool ground_due = ground_rate_.due(now), rab_due = rab_rate_.due(now);
    if (ground_due || rab_due) publishBoards(env, ground_due, rab_due);
    if (scan_rate_.due(now)) {
      for (std::size_t i = 0; i < robots_.size(); ++i) {
        Robot& r = robots_[i];
        if (r.proximity == nullptr || r.proximity->stamp == r.scan_published || r.proximity->distances.empty()) continue;
        r.scan_published = r.proximity->stamp;
        const ProximityMeasurement& p = *r.proximity;
        transport_->publishScan(i, toSeconds(p.stamp), p.range, p.radius, p.angles, p.distances, p.readings);
      }
    }
    if (image_rate_.due(now)) {
      for (std::size_t i = 0; i < robots_.size(); ++i) {
        Robot& r = robots_[i];
        if (r.camera == nullptr || r.camera->stamp == r.image_published || r.camera->image.rgb.empty()) continue;
        r.image_published = r.camera->stamp;
        transport_->publishImage(i, toSeconds(r.camera->stamp), r.camera->image.width, r.camera->image.height,
                                 r.camera->view.fov_deg, r.camera->image.rgb);
      }
    }
    for (std::size_t k = 0; k < operators_.size(); ++k) {
      Operator& o = operators_[k];
      if (o.force_rate.period == 0) {
        o.force_rate.period = periodOf(o.op->forceRateHz(), env.timestep());
        o.force_rate.next = now;
      }
      if (o.force_rate.due(now)) transport_->publishForce(robots_.size() + k, t, array3(o.op->force()));
    }
    transport_->commit();  // serialised and sent on the transport's own thread
    // what publishing costs the stepping thread, for the log (the first 2^16 publishing steps)
    if ((clock_due || imu_due || odom_due) && publish_costs_.size() < publish_costs_.capacity())
      publish_costs_.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  }

  /// After the world was put back to its start (a reset): the rates and lock-step start again.
  void restarted() {
    for (Rate* r : {&odom_rate_, &imu_rate_, &clock_rate_, &range_rate_, &image_rate_, &scan_rate_, &ground_rate_, &rab_rate_})
      r->next = 0;
    for (Robot& r : robots_) r.range_published = r.image_published = r.scan_published = r.ground_published = -1;
    for (Operator& o : operators_) o.force_rate.next = 0;
    waiting_for_ = cutoff_ = -1;
    held_.clear();
  }

  void shutdown(Environment& env) override {
    if (transport_) {
      logSummary(env);
      close(*transport_);
    }
    transport_.reset();
  }

 protected:
  /// The bridge's transport for these robots; throws std::exception (its message becomes the
  /// scene's error) when it cannot start.
  virtual std::unique_ptr<Transport> open(Environment& env, const Descriptor& params,
                                          const std::vector<RobotTopics>& robots) = 0;
  /// Stops the transport (sending what is staged first).
  virtual void close(Transport& transport) = 0;
  /// "ros1", "ros2": the log lines' prefix.
  virtual const char* name() const = 0;
  /// Whether the transport publishes /tf, /tf_static, joint states and descriptions (RobotTopics::tf).
  virtual bool offersTransforms() const { return false; }
  /// A robot's description for RobotTopics::description (empty: none).
  virtual std::string describe(const Artifact&) const { return {}; }

 private:
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
  struct Robot {
    Artifact* artifact = nullptr;
    SetpointInterface* tracker = nullptr;
    CommandInterface* commands = nullptr;  // takes velocity commands
    const ImuMeasurement* imu = nullptr;
    const RangeMeasurement* range = nullptr;
    const CameraMeasurement* camera = nullptr;
    const ProximityMeasurement* proximity = nullptr;
    const GroundMeasurement* ground = nullptr;
    const RangeBearingMeasurement* rab = nullptr;
    std::vector<const PhysicNode*> parts;   // its other bodies: frames on /tf (RobotTopics::parts)
    std::vector<const PhysicNode*> joints;  // its hinges and sliders (RobotTopics::joints)
    Nanoseconds range_published = -1;             // the stamp of the range last published
    Nanoseconds image_published = -1;             // of the image last published
    Nanoseconds scan_published = -1;              // of the proximity readings last published
    Nanoseconds ground_published = -1;            // of the ground readings last published
    std::uint64_t setpoints = 0, velocities = 0;  // applied so far
    std::uint64_t joint_commands = 0;             // likewise
    std::uint64_t bad_poses = 0;                  // a ghost's poses refused (not finite, not a rotation)
  };

  struct Operator {
    OperatorInterface* op = nullptr;
    Rate force_rate;
    std::uint64_t velocities = 0, joys = 0;  // applied so far
    std::string name;                        // its extension's: its topics' namespace
  };

  // the ghosts' poses that arrived, in arrival order, stamped in simulated time. Lock-stepped,
  // only those stamped at or before the last odometry answered are applied (the later ones wait):
  // which poses a step uses is then the same in every run.
  void applyPoses(Environment& env) {
    const double now = toSeconds(env.time());
    const double wall = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    std::size_t kept = 0;
    for (PoseSample& p : held_) {
      if (p.stamp == 0)
        p.stamp = now;  // unstamped: now
      else if (wall_stamps_)
        p.stamp = now - (wall - p.stamp);
      if (lockstep_ && p.stamp > cutoff_ + 1e-9) {
        held_[kept++] = p;
        continue;
      }
      Robot& r = robots_[p.robot];
      const Pose pose{Vec3(p.position[0], p.position[1], p.position[2]),
                      Quat(p.orientation[0], p.orientation[1], p.orientation[2], p.orientation[3])};
      try {
        env.setExternalPose(r.artifact->name(), pose, p.stamp);
        ++poses_applied_;
      } catch (const std::invalid_argument& e) {
        // a glitch of the motion capture (a zero quaternion when it loses the body) drops that
        // sample, not the run
        if (r.bad_poses++ == 0)
          env.log(LogLevel::Warning, std::string(name()) + ": a pose of ghost '" + r.artifact->name() + "' was dropped (" +
                                         e.what() + "); later ones are counted at the end");
      }
    }
    held_.resize(kept);  // (only lock-stepped, so never wall-clock stamps: converted once)
  }

  // the operator extensions named, each before this one in the scene
  static std::vector<std::pair<std::string, OperatorInterface*>> operatorsOf(const Descriptor& params,
                                                                             const Environment& env) {
    std::vector<std::pair<std::string, OperatorInterface*>> out;
    std::istringstream names(params.get<std::string>("operators", ""));
    for (std::string n; names >> n;) {
      auto* op = dynamic_cast<OperatorInterface*>(env.extension(n));
      if (op == nullptr)
        throw params.errorAt("operators", "operators: '" + n + "' is not an operator extension (<extension name=\"" + n +
                                              "\" plugin=\"operator\" .../> before this one)");
      out.emplace_back(n, op);
    }
    return out;
  }

  static Rate rateOf(const Descriptor& params, const char* key, Nanoseconds every_step) {
    Rate r;
    r.period = periodOf(params.get<double>(key), every_step);
    return r;
  }
  // a rate's period; 0 Hz, or one above the step rate, is every step
  static Nanoseconds periodOf(double hz, Nanoseconds every_step) {
    return hz > 0 ? std::max(every_step, toNanoseconds(1.0 / hz)) : every_step;
  }
  static std::array<double, 3> array3(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
  static std::array<double, 4> array4(const Quat& q) { return {q.w(), q.x(), q.y(), q.z()}; }
  static void appendPose(std::vector<double>& out, const Pose& p) {
    const Quat& q = p.orientation;
    out.insert(out.end(), {p.position.x(), p.position.y(), p.position.z(), q.w(), q.x(), q.y(), q.z()});
  }

  // a message that cannot be used is dropped and counted, with a warning naming its topic the
  // first time (and a count per topic at the end): one bad message never stops the run
  void drop(Environment& env, const std::string& who, const char* topic, const std::string& why) {
    const std::string name = "/" + who + "/" + topic;
    if (dropped_[name]++ == 0)
      env.log(LogLevel::Warning, std::string(this->name()) + ": a message on " + name + " was dropped (" + why +
                                     "); later ones are counted at the end");
  }
  template <class F>
  void guarded(Environment& env, const std::string& who, const char* topic, F&& apply) {
    try {
      apply();
    } catch (const Error& e) {
      drop(env, who, topic, e.what());
    } catch (const std::invalid_argument& e) {
      drop(env, who, topic, e.what());
    }
  }

  void logSummary(Environment& env) const {
    for (const auto& [topic, count] : dropped_)
      env.log(LogLevel::Warning, std::string(name()) + ": " + std::to_string(count) + " message(s) on " + topic +
                                     " dropped (not finite, absurd, or not for this robot)");
    if (poses_applied_ > 0 || transport_->posesDropped() + held_dropped_ > 0) {
      std::uint64_t bad = 0;
      for (const Robot& r : robots_) bad += r.bad_poses;
      const AgeSummary ages = env.ghostAges();
      char text[320];
      std::snprintf(text, sizeof text,
                    "%s: %llu ghost poses applied, %llu refused, %llu dropped unread; pose age when used median "
                    "%.1f ms, p99 %.1f ms, max %.1f ms",
                    name(), static_cast<unsigned long long>(poses_applied_), static_cast<unsigned long long>(bad),
                    static_cast<unsigned long long>(transport_->posesDropped() + held_dropped_), 1e3 * ages.median, 1e3 * ages.p99,
                    1e3 * ages.max);
      env.log(LogLevel::Info, text);
    }
    // how quickly the controllers outside answered, and what publishing cost the stepping thread
    std::vector<double> rt = transport_->roundTrips();
    char line[240];
    if (!rt.empty()) {
      std::sort(rt.begin(), rt.end());
      std::snprintf(line, sizeof line,
                    "%s: %zu set-points answered odometry; round trip median %.2f ms, p99 %.2f ms, max %.2f ms", name(),
                    rt.size(), 1e3 * rt[rt.size() / 2], 1e3 * rt[rt.size() * 99 / 100], 1e3 * rt.back());
      env.log(LogLevel::Info, line);
    }
    if (!publish_costs_.empty()) {
      std::vector<double> c = publish_costs_;
      std::sort(c.begin(), c.end());
      std::snprintf(line, sizeof line,
                    "%s: publishing took the stepping thread median %.1f us, p99 %.1f us, max %.1f us per "
                    "publishing step (%zu steps)",
                    name(), 1e6 * c[c.size() / 2], 1e6 * c[c.size() * 99 / 100], 1e6 * c.back(), c.size());
      env.log(LogLevel::Info, line);
    }
  }

  std::unique_ptr<Transport> transport_;
  std::vector<Robot> robots_;
  std::vector<Operator> operators_;  // their topics follow the robots'
  std::map<std::string, std::uint64_t> dropped_;  // messages dropped, by topic
  Rate odom_rate_, imu_rate_, clock_rate_, range_rate_, image_rate_, scan_rate_, ground_rate_, rab_rate_;
  std::vector<std::uint8_t> bytes_;  // range-and-bearing names and payloads, reused

  // the ground sensors' readings, and the range-and-bearing messages received (each sensing step's,
  // as the receiver holds them when due)
  void publishBoards(const Environment& env, bool ground, bool rab) {
    for (std::size_t i = 0; i < robots_.size(); ++i) {
      Robot& r = robots_[i];
      if (ground && r.ground != nullptr && r.ground->stamp != r.ground_published) {
        r.ground_published = r.ground->stamp;
        values_.clear();
        for (std::size_t k = 0; k < r.ground->readings.size() && k < r.ground->colors.size(); ++k) {
          const Vec3& c = r.ground->colors[k];
          values_.insert(values_.end(), {r.ground->readings[k], c.x(), c.y(), c.z()});
        }
        transport_->publishGround(i, toSeconds(r.ground->stamp), values_);
      }
      if (!rab || r.rab == nullptr) continue;
      values_.clear();
      bytes_.clear();
      for (const RangeBearingMeasurement::Message& m : r.rab->messages) {
        const std::string& sender = env.artifact(m.sender).name();
        values_.insert(values_.end(), {m.range, m.bearing, m.elevation, double(sender.size()), double(m.data.size())});
        bytes_.insert(bytes_.end(), sender.begin(), sender.end());
        bytes_.insert(bytes_.end(), m.data.begin(), m.data.end());
      }
      transport_->publishRangeBearing(i, toSeconds(r.rab->stamp), values_, bytes_);
    }
  }
  bool wall_stamps_ = false;
  double cutoff_ = -1;                 // lock-step: poses stamped later wait
  std::vector<PoseSample> arrived_, held_;
  std::uint64_t poses_applied_ = 0, held_dropped_ = 0;
  std::vector<std::array<double, 3>> points_;  // a range's, reused
  std::vector<double> values_;                  // a robot's frames or joint states, reused
  bool lockstep_ = false;
  double lockstep_timeout_ = 2.0, connect_timeout_ = 10.0;
  bool answered_ = false;  // lock-step: every robot answered once
  bool connected_ = false;
  double waiting_for_ = -1;            // lock-step: the odometry time set-points must answer
  std::uint64_t received_seen_ = 0;    // Transport::received() when what arrived was last applied
  std::vector<double> publish_costs_;  // s, per publishing step (reserved at init)
};

}  // namespace ssx::bridge
