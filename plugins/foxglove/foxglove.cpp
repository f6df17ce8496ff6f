// foxglove: an extension that serves the run live to Foxglove (or Lichtblick, or any client of
// Foxglove's WebSocket protocol: foxglove_server.hpp), on 127.0.0.1 unless told otherwise. In
// Foxglove: Open connection, Foxglove WebSocket, ws://127.0.0.1:8765.
//
// Channels, JSON-encoded with JSON Schemas; the first five are a recording's (ssx record), so one
// Foxglove layout serves a run live and its recording:
// - /tf (foxglove.FrameTransforms): every body's pose, "world" -> the body's name;
// - /scene (foxglove.SceneUpdate): every artifact's shapes, each in its body's frame (sent once);
// - /ssx/timing (ssx.StepTiming): the last step's cost per phase, ms;
// - /ssx/sensors (ssx.Sensors), /ssx/commands (ssx.Commands): every robot's latest measurements and
//   current command;
// - /ssx/run (ssx.RunStatus): simulated time, the real-time factor, late steps so far, paused;
// - each robot's own (the first robot_channels robots): /ROBOT/odom (ssx.Odometry: its pose and
//   velocities in the world frame), /ROBOT/imu (ssx.Imu: its first IMU's reading), /ROBOT/command
//   (ssx.Command), /ROBOT/sensors (ssx.RobotSensors: its entry of /ssx/sensors) and /ROBOT/metrics
//   (ssx.Metrics: what its driver and sensors publish as ssx::MetricSource).
// Messages are stamped with the simulated time, which the server also sends as its time.
//
// What the stepping thread does is kept short: at rate_hz per wall-clock second it copies the
// poses and velocities it needs (only of what a client subscribed to) and hands them to a thread of
// the extension's own, which writes the JSON; the server's threads send it. The sensors' latest
// measurements and the commands are copied likewise (detail::RunSample), only while a client
// subscribes. While that thread has not yet taken the last snapshot, no new one is copied.
//
// Parameters: kParameters below, or `ssx plugins --params foxglove`.
#include "foxglove_server.hpp"

#include "../common/web_access.hpp"
#include "base/json.hpp"
#include "record/foxglove.hpp"
#include "record/run_channels.hpp"

#include <ssx/command.hpp>
#include <ssx/environment.hpp>
#include <ssx/error.hpp>
#include <ssx/metrics.hpp>
#include <ssx/plugin_abi.hpp>
#include <ssx/recording.hpp>


#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace ssx::plugins {

namespace {

using detail::appendNumber;
using detail::appendString;

enum Fixed : std::size_t { kTf, kScene, kTiming, kSensors, kCommands, kRun, kFixedChannels };
// each robot's own channels, after the fixed ones: channel kFixedChannels + robot * kPerRobot + k
enum PerRobot : std::size_t { kOdom, kImu, kCommand, kRobotSensors, kMetrics, kPerRobot };

const char* const kRunSchema =
    R"j({"title":"ssx.RunStatus","description":"the run: simulated time (s), real-time factor since the last message, steps late so far (real-time runs), paused","type":"object","properties":{)j"
    R"j("time":{"type":"number"},"step":{"type":"integer"},"realtime_factor":{"type":"number"},"late_steps":{"type":"integer"},"paused":{"type":"boolean"}}})j";
const char* const kImuSchema =
    R"j({"title":"ssx.Imu","description":"a robot's first IMU: specific force (m/s^2) and turn rate (rad/s) in the sensor's frame, stamped when measured","type":"object","properties":{)j"
    R"j("timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},"frame_id":{"type":"string"},)j"
    R"j("accelerometer":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},)j"
    R"j("gyroscope":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}}}})j";
const char* const kCommandSchema =
    R"j({"title":"ssx.Command","description":"a robot's current command: its level (position, velocity, attitude, rates, rotors, wheels) and values in the column order of Python's set_commands","type":"object",)j"
    R"j("properties":{"level":{"type":"string"},"values":{"type":"array","items":{"type":"number"}}}})j";
const char* const kRobotSensorsSchema =
    R"j({"title":"ssx.RobotSensors","description":"a robot's latest measurements by sensor index, as /ssx/sensors has them","type":"object",)j"
    R"j("additionalProperties":{"type":"object","properties":{"kind":{"type":"string"},"stamp":{"type":"number"}}}})j";
const char* const kMetricsSchema =
    R"j({"title":"ssx.Metrics","description":"the numbers a robot's driver and sensors publish (ssx::MetricSource), by name with their unit; null when there is none now","type":"object",)j"
    R"j("additionalProperties":{"type":["number","null"]}})j";
const char* const kOdometrySchema =
    R"j({"title":"ssx.Odometry","description":"a robot's pose (m, quaternion) and velocities (m/s, rad/s) in the world frame","type":"object","properties":{)j"
    R"j("timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},"frame_id":{"type":"string"},"child_frame_id":{"type":"string"},)j"
    R"j("position":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},)j"
    R"j("orientation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}},)j"
    R"j("linear_velocity":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},)j"
    R"j("angular_velocity":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}}}})j";

// what the stepping thread hands to the extension's thread
struct Snapshot {
  Nanoseconds time = 0;
  bool tf = false;
  std::vector<float> positions, orientations;  // every body (N x 3, N x 4 w x y z), when /tf is wanted
  std::vector<std::pair<std::size_t, BodyState>> odometry;  // (robot, its first body's state) of those wanted
  std::vector<std::pair<std::size_t, std::string>> ready;  // (channel, JSON) made on the stepping thread
  bool sensors = false, commands = false;
  detail::RunSample sample;  // the sensors and commands, when wanted
  // robots' own channels: the sensors of those whose /ROBOT/imu or /ROBOT/sensors is wanted (a
  // sample per robot, kept with the snapshot), the commands of those whose /ROBOT/command is
  std::vector<detail::RunSample> robot_samples;
  std::vector<std::size_t> sensed;
  std::vector<std::pair<std::size_t, Command>> robot_commands;
};

void appendXyz(std::string& out, const char* name, double x, double y, double z) {
  out += '"';
  out += name;
  out += "\":{\"x\":";
  appendNumber(out, x);
  out += ",\"y\":";
  appendNumber(out, y);
  out += ",\"z\":";
  appendNumber(out, z);
  out += '}';
}

std::string imuJson(const std::string& frame, const ImuMeasurement& m) {
  const Nanoseconds stamp = std::max<Nanoseconds>(0, m.stamp);
  std::string out = R"({"timestamp":{"sec":)" + std::to_string(stamp / 1'000'000'000) + R"(,"nsec":)" +
                    std::to_string(stamp % 1'000'000'000) + R"(},"frame_id":)";
  appendString(out, frame);
  out += ',';
  appendXyz(out, "accelerometer", m.accelerometer.x(), m.accelerometer.y(), m.accelerometer.z());
  out += ',';
  appendXyz(out, "gyroscope", m.gyroscope.x(), m.gyroscope.y(), m.gyroscope.z());
  return out + "}";
}

std::string odometryJson(Nanoseconds time, const std::string& name, const BodyState& s) {
  std::string out = R"({"timestamp":{"sec":)" + std::to_string(time / 1'000'000'000) + R"(,"nsec":)" +
                    std::to_string(time % 1'000'000'000) + R"(},"frame_id":"world","child_frame_id":)";
  appendString(out, name);
  out += ',';
  appendXyz(out, "position", s.pose.position.x(), s.pose.position.y(), s.pose.position.z());
  const Quat& q = s.pose.orientation;
  out += R"(,"orientation":{"x":)";
  appendNumber(out, q.x());
  out += ",\"y\":";
  appendNumber(out, q.y());
  out += ",\"z\":";
  appendNumber(out, q.z());
  out += ",\"w\":";
  appendNumber(out, q.w());
  out += "},";
  appendXyz(out, "linear_velocity", s.linear_velocity.x(), s.linear_velocity.y(), s.linear_velocity.z());
  out += ',';
  appendXyz(out, "angular_velocity", s.angular_velocity.x(), s.angular_velocity.y(), s.angular_velocity.z());
  return out + "}";
}

}  // namespace

class Foxglove final : public SimulationExtension {
 public:
  static constexpr const char* kDoc =
      "the run live in Foxglove (its WebSocket protocol): transforms, the scene, timing, sensors, commands and each "
      "robot's odometry, on 127.0.0.1 by default";
  static constexpr ssx_plugin_param kParameters[] = {
      param::integer("port", "8765", param::atLeast(0) & param::atMost(65535),
                     "TCP port (ws://ADDR:PORT, Foxglove's default); 0: a free one, said when the run starts"),
      param::text("bind", "127.0.0.1",
                  "address listened on; another than 127.0.0.1 needs the token printed at start in the URL"),
      param::real("rate_hz", "30", "Hz", param::positive() & param::atMost(240),
                  "messages per channel per wall-clock second, at most"),
      param::integer("max_clients", "4", param::atLeast(1) & param::atMost(64), "clients connected at once, at most"),
      param::integer(
          "robot_channels", "1000", param::atLeast(0) & param::atMost(100000),
          "robots that get channels of their own (the first ones): odometry, IMU, command, sensors, metrics"),
  };

  // before anything is bound: the address is one address
  static void validate(const Descriptor& params, const PluginContext&) { web::checkBindAddress(params); }

  void init(Environment& env, const Descriptor& params) override {
    env_ = &env;
    control_ = &env.runControl();
    period_ = std::chrono::duration<double>(1.0 / params.get<double>("rate_hz"));
    const std::string bind = params.get<std::string>("bind");
    const bool loopback = web::isLoopback(bind);
    const std::string token = web::accessToken(bind);
    std::vector<foxglove::Channel> channels(kFixedChannels);
    channels[kTf] = {"/tf", "json", "foxglove.FrameTransforms", detail::kFrameTransformsSchema, "jsonschema"};
    channels[kScene] = {"/scene", "json", "foxglove.SceneUpdate", detail::kSceneUpdateSchema, "jsonschema"};
    channels[kTiming] = {"/ssx/timing", "json", "ssx.StepTiming", detail::kTimingSchema, "jsonschema"};
    channels[kSensors] = {"/ssx/sensors", "json", "ssx.Sensors", detail::kSensorsSchema, "jsonschema"};
    channels[kCommands] = {"/ssx/commands", "json", "ssx.Commands", detail::kCommandsSchema, "jsonschema"};
    channels[kRun] = {"/ssx/run", "json", "ssx.RunStatus", kRunSchema, "jsonschema"};
    // a robot: an artifact that moves (the bodies are known from the first step; the channels now)
    const auto most = static_cast<std::size_t>(params.get<std::int64_t>("robot_channels"));
    for (std::size_t i = 0; i < env.artifactCount() && robots_.size() < most; ++i) {
      const Artifact& a = std::as_const(env).artifact(i);
      bool moves = false;
      for (std::size_t r = 0; r < a.rootCount(); ++r) moves = moves || !a.root(r).isStatic();
      if (!moves) continue;
      robots_.push_back({i, a.name(), nullptr, nullptr, {}});
      const std::string at = "/" + a.name();
      channels.push_back({at + "/odom", "json", "ssx.Odometry", kOdometrySchema, "jsonschema"});
      channels.push_back({at + "/imu", "json", "ssx.Imu", kImuSchema, "jsonschema"});
      channels.push_back({at + "/command", "json", "ssx.Command", kCommandSchema, "jsonschema"});
      channels.push_back({at + "/sensors", "json", "ssx.RobotSensors", kRobotSensorsSchema, "jsonschema"});
      channels.push_back({at + "/metrics", "json", "ssx.Metrics", kMetricsSchema, "jsonschema"});
    }
    try {
      server_ = std::make_unique<foxglove::Server>(bind, static_cast<int>(params.get<std::int64_t>("port")), token,
                                                   static_cast<int>(params.get<std::int64_t>("max_clients")), "ssx",
                                                   std::move(channels));
    } catch (const std::exception& e) {
      throw params.error(std::string("foxglove: ") + e.what());
    }
    url_ = "ws://" + (loopback ? std::string("127.0.0.1") : bind) + ":" + std::to_string(server_->port()) +
           (token.empty() ? "" : "/?token=" + token);
    env.log(LogLevel::Info, "foxglove: " + url_ + " (in Foxglove: Open connection, Foxglove WebSocket)");
    last_wall_ = std::chrono::steady_clock::now() - std::chrono::hours(1);
    builder_ = std::thread([this] { build(); });
  }

  void afterStep(Environment& env) override {
    if (!begun_) {  // the bodies exist from the first step on
      begun_ = true;
      bodies_ = recordedBodies(env);
      for (const RecordedBody& b : bodies_) {
        names_.push_back(b.name);
        frames_.push_back({b.node->bodyIndex(), b.node->poseInBody()});
      }
      for (Robot& r : robots_) {
        for (const RecordedBody& b : bodies_)
          if (b.name == r.name && &b.node->artifact() == &std::as_const(env).artifact(r.artifact)) r.node = b.node;
        const Artifact& a = std::as_const(env).artifact(r.artifact);
        r.commandable = dynamic_cast<const CommandInterface*>(a.driver());
        if (const auto* m = dynamic_cast<const MetricSource*>(a.driver())) r.metrics.push_back(m);
        for (std::size_t k = 0; k < a.sensorCount(); ++k)
          if (const auto* m = dynamic_cast<const MetricSource*>(&a.sensor(k))) r.metrics.push_back(m);
      }
      server_->publish(kScene, static_cast<std::uint64_t>(std::max<Nanoseconds>(0, env.time())),
                       detail::runSceneUpdate(env, bodies_));
    }
    const TimingRecorder& timing = env.timing();
    if (timing.size() >= 2 && timing[timing.size() - 2].lateness > 0) ++late_;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_wall_ < period_ && !control_->paused()) return;
    const auto started = std::chrono::steady_clock::now();
    const double wall = std::chrono::duration<double>(now - last_wall_).count();
    const double rtf = last_sim_ >= 0 && wall < 60 ? (toSeconds(env.time()) - last_sim_) / wall : 0;
    last_wall_ = now;
    last_sim_ = toSeconds(env.time());
    const auto time = static_cast<std::uint64_t>(std::max<Nanoseconds>(0, env.time()));
    server_->publishTime(time);
    if (!server_->anyWanted()) return;  // (nobody subscribed: nothing to copy, nothing to write)
    {
      // the extension's thread has not yet taken the last snapshot: a new one would only replace
      // it, copied for nothing (at 10,000 robots, 9 of 10 copies were)
      std::lock_guard lock(mutex_);
      if (pending_) {
        ++behind_;
        return;
      }
    }

    std::unique_ptr<Snapshot> s = takeSpare();
    s->time = env.time();
    s->tf = server_->wanted(kTf);
    s->positions.clear(), s->orientations.clear(), s->odometry.clear(), s->ready.clear();
    if (s->tf) {
      s->positions.resize(3 * frames_.size());
      s->orientations.resize(4 * frames_.size());
      float* position = s->positions.data();
      float* orientation = s->orientations.data();
      for (const Frame& f : frames_) {
        const Pose pose = env.bodyState(f.body).pose * f.in_body;
        const Quat& q = pose.orientation;
        for (const double v : {pose.position.x(), pose.position.y(), pose.position.z()})
          *position++ = static_cast<float>(v);
        for (const double v : {q.w(), q.x(), q.y(), q.z()}) *orientation++ = static_cast<float>(v);
      }
    }
    s->sensed.clear(), s->robot_commands.clear();
    for (std::size_t r = 0; r < robots_.size(); ++r) {
      const Robot& robot = robots_[r];
      const std::size_t channel = kFixedChannels + r * kPerRobot;
      if (robot.node != nullptr && server_->wanted(channel + kOdom))
        s->odometry.emplace_back(r, env.bodyState(robot.node->bodyIndex()).attached(robot.node->poseInBody()));
      if (server_->wanted(channel + kImu) || server_->wanted(channel + kRobotSensors)) {
        if (s->robot_samples.size() <= r) s->robot_samples.resize(robots_.size());
        s->robot_samples[r].takeSensorsOf(env, robot.artifact);
        s->sensed.push_back(r);
      }
      if (robot.commandable != nullptr && server_->wanted(channel + kCommand))
        s->robot_commands.emplace_back(r, robot.commandable->currentCommand());
      if (!robot.metrics.empty() && server_->wanted(channel + kMetrics))
        s->ready.emplace_back(channel + kMetrics, metricsJson(robot));
    }
    if (server_->wanted(kTiming) && timing.size() > 0)
      s->ready.emplace_back(kTiming, detail::timingJson(timing[timing.size() - 1], env.physics().contactCount()));
    s->sensors = server_->wanted(kSensors);
    s->commands = server_->wanted(kCommands);
    if (s->sensors) s->sample.takeSensors(env);
    if (s->commands) s->sample.takeCommands(env);
    if (server_->wanted(kRun)) {
      std::string run = R"({"time":)";
      appendNumber(run, toSeconds(env.time()));
      run += R"(,"step":)" + std::to_string(env.stepCount()) + R"(,"realtime_factor":)";
      appendNumber(run, rtf);
      run += R"(,"late_steps":)" + std::to_string(late_) + R"(,"paused":)" + (control_->paused() ? "true" : "false") + "}";
      s->ready.emplace_back(kRun, std::move(run));
    }
    {
      std::lock_guard lock(mutex_);
      pending_ = std::move(s);
      changed_.notify_all();
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
    ++taken_, taken_ms_sum_ += ms, taken_ms_max_ = std::max(taken_ms_max_, ms);
  }

  void shutdown(Environment& env) override {
    stopBuilding();
    if (!server_) return;
    const foxglove::ServerCounts c = server_->counts();
    server_->stop();
    env.log(LogLevel::Info, "foxglove: " + std::to_string(c.messages_published) + " messages published, " +
                                std::to_string(c.messages_sent) + " sent, " + std::to_string(c.messages_skipped) +
                                " skipped by slow clients, " + std::to_string(behind_) +
                                " snapshots left out while its thread was behind, " +
                                std::to_string(c.requests_dropped) + " requests dropped, " +
                                std::to_string(c.clients_refused) + " clients refused");
    if (taken_ > 0) {
      char text[160];
      std::snprintf(text, sizeof text, "foxglove: a snapshot took %.3f ms on the stepping thread on average, %.3f ms at most",
                    taken_ms_sum_ / static_cast<double>(taken_), taken_ms_max_);
      env.log(LogLevel::Info, text);
    }
    server_.reset();
  }

  ~Foxglove() override {
    stopBuilding();
    if (server_) server_->stop();
  }

 private:
  struct Robot {
    std::size_t artifact;
    std::string name;
    const PhysicNode* node;  // its first body's head, from the first step on
    const CommandInterface* commandable;       // its driver, when it takes commands (from the first step on)
    std::vector<const MetricSource*> metrics;  // its driver and sensors that publish metrics
  };

  // /ROBOT/metrics: {"name": value, ...} of its driver's and sensors' metrics (made on the stepping
  // thread: MetricSource is called there only; a few values)
  std::string metricsJson(const Robot& robot) {
    metric_values_.clear();
    for (const MetricSource* m : robot.metrics) m->metrics(metric_values_);
    std::string out = "{";
    for (const Metric& m : metric_values_) {
      if (out.size() > 1) out += ',';
      appendString(out, m.name);
      out += ':';
      appendNumber(out, m.value);
    }
    return out + "}";
  }

  // snapshots are kept for the next ones, never freed while running: one being filled, one
  // waiting and one being written is the most there can be, and a fresh one at 10,000 robots is
  // megabytes of new memory to grow and fault in on the stepping thread (it was, whenever the
  // extension's thread fell behind: 14 ms a snapshot of the sensors)
  std::unique_ptr<Snapshot> takeSpare() {
    std::lock_guard lock(mutex_);
    if (spares_.empty()) return std::make_unique<Snapshot>();
    std::unique_ptr<Snapshot> s = std::move(spares_.back());
    spares_.pop_back();
    return s;
  }
  void giveSpare(std::unique_ptr<Snapshot> s) {
    std::lock_guard lock(mutex_);
    spares_.push_back(std::move(s));
  }

  // the extension's thread: each snapshot's JSON, published
  void build() {
    web::lowerThisThreadsPriority();  // (behind, the next snapshots are left out until it takes this one: counted)
    for (;;) {
      std::unique_ptr<Snapshot> s;
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return stopping_ || pending_ != nullptr; });
        if (stopping_) return;
        s = std::move(pending_);
      }
      const auto time = static_cast<std::uint64_t>(std::max<Nanoseconds>(0, s->time));
      if (s->tf) server_->publish(kTf, time, detail::frameTransforms(s->time, names_, s->positions, s->orientations));
      for (const auto& [r, state] : s->odometry)
        server_->publish(kFixedChannels + r * kPerRobot + kOdom, time, odometryJson(s->time, robots_[r].name, state));
      for (const std::size_t r : s->sensed) {
        const std::size_t channel = kFixedChannels + r * kPerRobot;
        const detail::RunSample& sample = s->robot_samples[r];
        const ImuMeasurement* imu = sample.firstImu();
        if (imu != nullptr && server_->wanted(channel + kImu))
          server_->publish(channel + kImu, time, imuJson(robots_[r].name, *imu));
        if (server_->wanted(channel + kRobotSensors))
          server_->publish(channel + kRobotSensors, time, sample.artifactSensorsJson(*env_));
      }
      for (const auto& [r, command] : s->robot_commands)
        server_->publish(kFixedChannels + r * kPerRobot + kCommand, time, commandJson(command));
      if (s->sensors) server_->publish(kSensors, time, s->sample.sensorsJson(*env_));
      if (s->commands) server_->publish(kCommands, time, s->sample.commandsJson(*env_));
      for (auto& [channel, json] : s->ready) server_->publish(channel, time, std::move(json));
      giveSpare(std::move(s));
    }
  }

  void stopBuilding() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
      changed_.notify_all();
    }
    if (builder_.joinable()) builder_.join();
  }

  const Environment* env_ = nullptr;  // (the extension's thread reads only its artifacts' names)
  RunControl* control_ = nullptr;
  std::unique_ptr<foxglove::Server> server_;
  std::string url_;
  std::chrono::duration<double> period_{1.0 / 30};
  std::chrono::steady_clock::time_point last_wall_;
  double last_sim_ = -1;
  bool begun_ = false;
  std::vector<RecordedBody> bodies_;
  std::vector<std::string> names_;
  // each recorded body's frame: its body (fixed from the first step on) and where the frame is in
  // it, read once: a snapshot of /tf then reads only the bodies' states
  struct Frame {
    int body;
    Pose in_body;
  };
  std::vector<Frame> frames_;
  std::vector<Robot> robots_;
  std::vector<Metric> metric_values_;  // (kept: metricsJson's)
  std::int64_t late_ = 0;
  // the stepping thread and the extension's thread
  std::mutex mutex_;
  std::condition_variable changed_;
  std::unique_ptr<Snapshot> pending_;
  std::vector<std::unique_ptr<Snapshot>> spares_;
  bool stopping_ = false;
  std::uint64_t behind_ = 0;  // publishing times left out: the last snapshot was still waiting
  std::thread builder_;
  std::uint64_t taken_ = 0;
  double taken_ms_sum_ = 0, taken_ms_max_ = 0;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_EXTENSION(ssx::plugins::Foxglove, "foxglove"));
