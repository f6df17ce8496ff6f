// viewer: an extension that serves a live 3D view of the run to web browsers (three.js), on
// 127.0.0.1 unless told otherwise. The page gets the scene once (every artifact's shapes, a model
// per render tree, so that a swarm's members are drawn as instances of one mesh) and then frames of
// every body's pose at up to rate_hz per wall-clock second.
//
// Frames: frame.hpp (the real-time factor since the last frame, the late steps so far, the step).
//
// Steering the run: {"type":"pause"}, {"type":"resume"}, {"type":"step"} (one step while paused) and
// {"type":"rate","factor":F} (the real-time factor of a real-time run), through Environment::runControl.
//
// After the poses: uint32 L, then L bytes of JSON, {"run":{"factor":F,"paused":B},"details":[...]}:
// the real-time factor set from a page (0: the run's own) and whether the run is paused; the newest
// velocity command a step used since the last frame ("command":{"page":P,"sent":S,"waited_ms":D}:
// the page's own number and time stamp, "page" and "sent" in its message, and how long it waited
// for its step); and, for
// each body a page has selected ({"type":"select","body":I}, asked again each second, forgotten 3 s after
// the last), its name, linear and angular velocity (world frame), current command
// (ssx::commandJson) and latest measurements (ssx::measurementJson, with the sensor's class).
//
// Teleoperation: a page sends {"type":"velocity","body":I,"v":[vx,vy,vz],"yaw_rate":W} (m/s in the
// world frame, rad/s), or with "all":true instead of a body for every robot whose driver takes
// velocity commands (the whole formation, moved as one), while a key or stick is held; before the
// next step the drivers get it as a velocity-level command (ssx::CommandInterface). No message for
// 0.5 s of the wall clock (a key released, a page gone) stops the robots: velocity 0, where they are.
//
// Replaying (`ssx replay FILE --view`, the parameter `recording`): the page gets the recorded
// scene with "replay":{"start":S,"end":E} (s) and frames of the recorded poses, played by a thread
// of the viewer's own on the wall clock (Playback): pause, resume, step (one sample), rate (the
// speed) and {"type":"seek","time":T} (the page's slider). Nothing is steered; a selected robot's
// details are as recorded (replay_details.hpp).
//
// Parameters: kParameters below, or `ssx plugins --params viewer`.
#include "frame.hpp"
#include "playback.hpp"
#include "replay_details.hpp"
#include "scene_shapes.hpp"
#include "viewer_server.hpp"

#include "../common/web_access.hpp"
#include <ssx/command.hpp>
#include <ssx/environment.hpp>
#include <ssx/error.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>
#include <ssx/recording.hpp>


#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <condition_variable>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

extern "C" {
extern const char ssx_viewer_index_html[], ssx_viewer_index_html_end[];
extern const char ssx_viewer_js[], ssx_viewer_js_end[];
extern const char ssx_viewer_three_js[], ssx_viewer_three_js_end[];
extern const char ssx_viewer_orbit_js[], ssx_viewer_orbit_js_end[];
}

namespace ssx::plugins {

namespace {

using viewer::appendNumber;
using viewer::appendString;
using viewer::jsonNumber;
using viewer::MeshTable;
using viewer::shapes;

}  // namespace

class Viewer final : public SimulationExtension {
 public:
  static constexpr const char* kDoc = "a live 3D view of the run in a web browser (three.js), on 127.0.0.1 by default";
  static constexpr ssx_plugin_param kParameters[] = {
      param::integer("port", "8765", param::atLeast(0) & param::atMost(65535),
                     "TCP port of the page (http://ADDR:PORT/); 0: a free one, said when the run starts"),
      param::text("bind", "127.0.0.1",
                  "address listened on; another than 127.0.0.1 needs the token printed at start in the page's URL"),
      param::real("rate_hz", "30", "Hz", param::positive() & param::atMost(240),
                  "frames sent to the pages per wall-clock second, at most"),
      param::integer("max_clients", "4", param::atLeast(1) & param::atMost(64), "pages connected at once, at most"),
      param::flag("wait", "false",
                  "hold the run after its first step until a page connects (ssx run --view-wait)"),
      param::text("recording", "",
                  "play this recording (MCAP) on the page instead of the run, as ssx replay FILE --view does; "
                  "default: none"),
  };

  // before anything is opened or bound: the address is one address (civetweb would take "+" or a
  // list of ports in it and listen wider than asked), the recording a regular file
  static void validate(const Descriptor& params, const PluginContext&) {
    web::checkBindAddress(params);
    if (const std::string file = params.has("recording") ? params.get<std::string>("recording") : ""; !file.empty()) {
      std::error_code ec;
      const auto status = std::filesystem::status(file, ec);
      if (!std::filesystem::exists(status)) throw params.error("recording '" + file + "' does not exist");
      if (!std::filesystem::is_regular_file(status))
        throw params.error("recording '" + file + "' is not a regular file (a directory, a FIFO, a device or a "
                           "socket): give a recording (.mcap) file");
    }
  }

  void init(Environment& env, const Descriptor& params) override {
    control_ = &env.runControl();
    const int port = static_cast<int>(params.get<std::int64_t>("port"));
    const std::string bind = params.get<std::string>("bind");
    period_ = std::chrono::duration<double>(1.0 / params.get<double>("rate_hz"));
    pacer_ = viewer::FramePacer(period_);
    wait_ = params.get<bool>("wait");
    if (const std::string file = params.has("recording") ? params.get<std::string>("recording") : ""; !file.empty()) {
      try {
        recording_ = std::make_unique<Recording>(file);
      } catch (const std::exception& e) {
        throw params.error(std::string("viewer: ") + e.what());
      }
      if (recording_->times().empty()) throw params.error("viewer: " + file + " holds no pose sample to play");
      playback_ = std::make_unique<viewer::Playback>(recording_->times());
      playback_->resume();  // playing at once (here, not in its thread: a pause a page sends before it starts holds)
      replay_details_ = std::make_unique<viewer::ReplayDetails>(*recording_);
    }
    const bool loopback = web::isLoopback(bind);
    const std::string token = web::accessToken(bind);
    const std::vector<viewer::Asset> assets{
        {"/", "text/html; charset=utf-8", ssx_viewer_index_html,
         static_cast<std::size_t>(ssx_viewer_index_html_end - ssx_viewer_index_html)},
        {"/viewer.js", "text/javascript; charset=utf-8", ssx_viewer_js, static_cast<std::size_t>(ssx_viewer_js_end - ssx_viewer_js)},
        {"/three.min.js", "text/javascript; charset=utf-8", ssx_viewer_three_js,
         static_cast<std::size_t>(ssx_viewer_three_js_end - ssx_viewer_three_js)},
        {"/OrbitControls.js", "text/javascript; charset=utf-8", ssx_viewer_orbit_js,
         static_cast<std::size_t>(ssx_viewer_orbit_js_end - ssx_viewer_orbit_js)}};
    try {
      server_ = std::make_unique<viewer::Server>(
          bind, port, token, static_cast<int>(params.get<std::int64_t>("max_clients")), assets, sceneJson(env),
          [this](const std::string& text) { return onMessage(text); });
    } catch (const std::exception& e) {
      throw params.error(std::string("viewer: ") + e.what());
    }
    url_ = "http://" + (loopback ? std::string("127.0.0.1") : bind) + ":" + std::to_string(server_->port()) + "/" +
           (token.empty() ? "" : "?token=" + token);
    env.log(LogLevel::Info, "viewer: " + url_);
    last_wall_ = std::chrono::steady_clock::now() - std::chrono::hours(1);
  }

  // a page's command enters the simulation here, before the step's drivers
  void beforeStep(Environment&) override {
    std::lock_guard lock(mutex_);
    if (teleop_.body < 0 && !teleop_.all) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - teleop_.received > std::chrono::milliseconds(500)) {  // the dead-man rule
      forEachSteered([](CommandInterface& driver) { driver.setCommand(Command::velocityYawRate(Vec3::Zero(), 0)); });
      teleop_.body = -1;
      teleop_.all = false;
      ++teleop_stops_;
      return;
    }
    if (!teleop_.fresh) return;
    const Command command = Command::velocityYawRate(teleop_.velocity, teleop_.yaw_rate);
    forEachSteered([&](CommandInterface& driver) { driver.setCommand(command); });
    teleop_.fresh = false;
    delays_ms_.push_back(std::chrono::duration<double, std::milli>(now - teleop_.received).count());
    used_ = {teleop_.page, teleop_.sent, delays_ms_.back()};
  }

  void afterStep(Environment& env) override {
    if (!begun_) {
      // the bodies exist from the first step on: each artifact's dynamic roots and joined parts,
      // as the recorder has them; the pages get the scene with them now
      begun_ = true;
      std::lock_guard lock(mutex_);  // (pages' commands look the bodies up)
      recorded_ = recordedBodies(env);
      for (const RecordedBody& b : recorded_) {
        const PhysicNode& head = *b.node;
        nodes_.push_back(&head);
        names_.push_back(b.name);
        const Pose& in_body = head.poseInBody();
        // (which drivers take velocity commands, known once: a page's command looks it up; a
        // page steers an artifact by its first body)
        auto* driver = dynamic_cast<CommandInterface*>(env.artifact(head.artifact().index()).driver());
        const bool first = b.name == head.artifact().name();
        CommandInterface* steer =
            first && driver != nullptr && driver->acceptsCommand(CommandLevel::Velocity) ? driver : nullptr;
        steerable_ += steer != nullptr;
        bodies_.push_back({head.bodyIndex(), in_body,
                           in_body.position.isZero(0) && in_body.orientation.coeffs() == Quat::Identity().coeffs(), steer});
      }
      if (recording_ && names_ != recording_->names())
        throw Error("viewer: the recording's " + std::to_string(recording_->names().size()) +
                    " bodies are not the scene's " + std::to_string(names_.size()) + " (a recording of another version?)");
      server_->setHello(sceneJson(env));
      if (recording_) player_ = std::thread([this] { play(); });
      // --view-wait: paused here until a page says hello (onMessage resumes it)
      if (wait_ && !recording_ && server_->counts().clients == 0) {
        waiting_ = true;
        control_->pause();
        env.log(LogLevel::Info, "viewer: the run waits for a page at " + url_);
      }
    }
    if (recording_) return;  // the frames are the recording's
    const TimingRecorder& timing = env.timing();
    if (timing.size() >= 2 && timing[timing.size() - 2].lateness > 0) ++late_;
    const auto now = std::chrono::steady_clock::now();
    // (and every step of a paused run: the one it was paused after, and each single step)
    if (!pacer_.due(now) && !control_->paused()) return;
    pacer_.sent(now);
    const double wall = std::chrono::duration<double>(now - last_wall_).count();
    const auto build_start = std::chrono::steady_clock::now();
    const double rtf = last_sim_ >= 0 && wall < 60 ? (toSeconds(env.time()) - last_sim_) / wall : 0;
    last_wall_ = now;
    last_sim_ = toSeconds(env.time());
    const std::uint32_t n = static_cast<std::uint32_t>(nodes_.size());
    float* f = viewer::beginFrame(frame_, {toSeconds(env.time()), static_cast<float>(rtf), late_,
                                           static_cast<std::uint64_t>(env.stepCount())}, n);
    for (std::size_t b = 0; b < nodes_.size(); ++b) {  // (each root node's pose from its body's state)
      const Pose& body = env.bodyState(bodies_[b].index).pose;
      const Pose pose = bodies_[b].at_body ? body : body * bodies_[b].in_body;
      const Quat& q = pose.orientation;
      for (const double v : {pose.position.x(), pose.position.y(), pose.position.z(), q.x(), q.y(), q.z(), q.w()})
        *f++ = static_cast<float>(v);
    }
    viewer::CommandEcho echo;
    {
      std::lock_guard lock(mutex_);
      std::swap(echo, used_);  // (said once)
    }
    viewer::endFrame(frame_, n, viewer::trailerJson(control_->realtimeFactor(), control_->paused(), detailsJson(env, now), echo));
    server_->publish(frame_);
    const double build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - build_start).count();
    ++built_, build_ms_sum_ += build_ms, build_ms_max_ = std::max(build_ms_max_, build_ms);
  }

  void shutdown(Environment& env) override {
    stopPlaying();
    if (!server_) return;
    if (!recording_) {  // the pages keep the last frame, and say how the run ended
      char summary[200];
      std::snprintf(summary, sizeof summary, "t = %.3f s after %lld steps, %lld of them late", toSeconds(env.time()),
                    static_cast<long long>(env.stepCount()), static_cast<long long>(late_));
      std::string end = R"({"type":"end","summary":)";
      appendString(end, summary);
      server_->farewell(end + "}", std::chrono::milliseconds(500));
    }
    const viewer::ServerCounts c = server_->counts();  // (with the pages still connected: what they missed)
    server_->stop();
    env.log(LogLevel::Info, "viewer: " + std::to_string(c.frames_published) + " frames published, " +
                                std::to_string(c.frames_sent) + " sent, " + std::to_string(c.frames_skipped) +
                                " skipped by slow pages, " + std::to_string(c.messages_dropped) + " messages dropped, " +
                                std::to_string(c.clients_refused) + " pages refused");
    if (built_ > 0) {
      char text[160];
      std::snprintf(text, sizeof text, "viewer: a frame took %.3f ms on the stepping thread on average, %.3f ms at most",
                    build_ms_sum_ / static_cast<double>(built_), build_ms_max_);
      env.log(LogLevel::Info, text);
    }
    if (!delays_ms_.empty()) {
      std::sort(delays_ms_.begin(), delays_ms_.end());
      char text[160];
      std::snprintf(text, sizeof text,
                    "viewer: %zu velocity commands from pages, from arrival to the step that used them median %.2f ms, "
                    "max %.2f ms; %llu dead-man stops",
                    delays_ms_.size(), delays_ms_[delays_ms_.size() / 2], delays_ms_.back(),
                    static_cast<unsigned long long>(teleop_stops_));
      env.log(LogLevel::Info, text);
    }
    server_.reset();
  }

  // a page's message (on a server thread): true when understood
  bool onMessage(const std::string& text) {
    if (text.find(R"("type":"hello")") != std::string::npos) {
      if (waiting_.exchange(false)) control_->resume();
      return true;
    }
    if (playback_) return onReplayMessage(text);
    // pause, single steps, resume and the real-time factor (Environment::runControl: any thread)
    if (text.find(R"("type":"pause")") != std::string::npos) return control_->pause(), true;
    if (text.find(R"("type":"resume")") != std::string::npos) return control_->resume(), true;
    if (text.find(R"("type":"step")") != std::string::npos) return control_->stepOnce(1), true;
    if (text.find(R"("type":"rate")") != std::string::npos) {
      const auto factor = jsonNumber(text, "factor");
      if (!factor || !(*factor >= kMinRealtimeFactor && *factor <= kMaxRealtimeFactor)) return false;
      control_->setRealtimeFactor(*factor);
      return true;
    }
    if (text.find(R"("type":"select")") != std::string::npos) return watch(text);
    if (text.find(R"("type":"velocity")") == std::string::npos) return false;
    const bool all = text.find(R"("all":true)") != std::string::npos;
    const auto body = all ? std::optional<double>(0) : jsonNumber(text, "body");
    const auto vx = jsonNumber(text, "v", 0), vy = jsonNumber(text, "v", 1), vz = jsonNumber(text, "v", 2);
    const auto yaw_rate = jsonNumber(text, "yaw_rate");
    if (!body || !vx || !vy || !vz || !yaw_rate || *body < 0 || *body != std::floor(*body)) return false;
    const Vec3 v(*vx, *vy, *vz);
    if (v.norm() > kMaxSpeed || std::abs(*yaw_rate) > kMaxYawRate) return false;
    std::lock_guard lock(mutex_);
    if (*body >= static_cast<double>(nodes_.size())) return false;
    const int index = all ? -1 : static_cast<int>(*body);
    if (steerable(all ? std::nullopt : std::optional<std::size_t>(static_cast<std::size_t>(*body))) == 0) return false;
    // (the page's own number and clock, ms: echoed, never interpreted)
    const auto sent = jsonNumber(text, "sent"), page = jsonNumber(text, "page");
    teleop_ = {index, all, v, *yaw_rate, std::chrono::steady_clock::now(), true, sent.value_or(-1), page.value_or(0)};
    return true;
  }

  ~Viewer() override {
    stopPlaying();
    if (server_) server_->stop();
  }

 private:
  // a page's {"type":"select","body":I}: its details sent with the frames for 3 s (`lock_it` false: mutex_ is held)
  bool watch(const std::string& text, bool lock_it = true) {
    const auto body = jsonNumber(text, "body");
    std::unique_lock lock(mutex_, std::defer_lock);
    if (lock_it) lock.lock();
    if (!body || *body < 0 || *body != std::floor(*body) || *body >= static_cast<double>(nodes_.size())) return false;
    const int index = static_cast<int>(*body);
    if (watched_.size() >= kMaxWatched && watched_.count(index) == 0) return false;
    details_asked_ |= watched_.count(index) == 0;
    watched_[index] = std::chrono::steady_clock::now();
    return true;
  }

  // the bodies a page selected in the last 3 s, the others forgotten (under mutex_)
  std::vector<int> stillWatched(std::chrono::steady_clock::time_point now) {
    std::erase_if(watched_, [&](const auto& w) { return now - w.second > std::chrono::seconds(3); });
    std::vector<int> bodies;
    for (const auto& w : watched_) bodies.push_back(w.first);
    return bodies;
  }

  // a page's message about the recording played: true when understood
  bool onReplayMessage(const std::string& text) {
    std::lock_guard lock(mutex_);
    if (text.find(R"("type":"pause")") != std::string::npos) return playback_->pause(), true;
    if (text.find(R"("type":"resume")") != std::string::npos) return playback_->resume(), true;
    if (text.find(R"("type":"step")") != std::string::npos) return playback_->stepOnce(), true;
    if (text.find(R"("type":"select")") != std::string::npos) return watch(text, false);
    if (text.find(R"("type":"rate")") != std::string::npos) {
      const auto factor = jsonNumber(text, "factor");
      return factor && playback_->setSpeed(*factor);
    }
    if (text.find(R"("type":"seek")") != std::string::npos) {
      const auto t = jsonNumber(text, "time");
      if (!t || *t < 0 || *t > 1e9) return false;
      playback_->seek(toNanoseconds(*t));
      return true;
    }
    return false;  // nothing to steer in a recording
  }

  // the playback thread: every period, the clock moved on and its sample sent (again at least
  // once a second, for pages that connect while it stands still)
  void play() {
    auto last = std::chrono::steady_clock::now(), sent = last - std::chrono::hours(1);
    std::size_t shown = static_cast<std::size_t>(-1);
    bool shown_paused = false;
    for (;;) {
      std::size_t k = 0;
      bool paused = false, asked = false;
      double speed = 1;
      std::vector<int> watched;
      {
        std::unique_lock lock(mutex_);
        if (playing_cv_.wait_for(lock, period_, [this] { return stop_playing_; })) return;
        const auto now = std::chrono::steady_clock::now();
        playback_->advance(std::chrono::duration<double>(now - last).count());
        last = now;
        k = playback_->sample(), paused = playback_->paused(), speed = playback_->speed();
        watched = stillWatched(now);
        asked = std::exchange(details_asked_, false);
      }
      if (k == shown && paused == shown_paused && !asked && last - sent < std::chrono::seconds(1)) continue;
      shown = k, shown_paused = paused, sent = last;
      const std::vector<float> p = recording_->positions(k), q = recording_->orientations(k);  // (q: w x y z)
      const std::uint32_t n = static_cast<std::uint32_t>(recording_->names().size());
      float* f = viewer::beginFrame(play_frame_, {toSeconds(recording_->times()[k]), paused ? 0.0f : static_cast<float>(speed), 0, k}, n);
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t a = 0; a < 3; ++a) *f++ = p[3 * i + a];
        *f++ = q[4 * i + 1], *f++ = q[4 * i + 2], *f++ = q[4 * i + 3], *f++ = q[4 * i];
      }
      // the selected robots as recorded: velocities from the poses, the command and sensors if recorded
      std::string details;
      try {
        for (const int b : watched)
          details += (details.empty() ? "[" : ",") +
                     replay_details_->json(k, static_cast<std::size_t>(b), nodes_[static_cast<std::size_t>(b)]->artifact().name());
      } catch (const std::exception&) {
        details.clear();  // (a damaged part of the file: the poses go on without details)
      }
      viewer::endFrame(play_frame_, n, viewer::trailerJson(speed, paused, details.empty() ? details : details + "]"));
      server_->publish(play_frame_);
    }
  }

  void stopPlaying() {
    {
      std::lock_guard lock(mutex_);
      stop_playing_ = true;
    }
    playing_cv_.notify_all();
    if (player_.joinable()) player_.join();
  }

  // how many robots a command to `body` (nothing: all) would steer (under mutex_)
  std::size_t steerable(std::optional<std::size_t> body) const {
    return body ? (bodies_[*body].steer != nullptr ? 1 : 0) : steerable_;
  }

  // each driver the current teleoperation steers (under mutex_, on the stepping thread)
  template <class F>
  void forEachSteered(F&& f) {
    if (!teleop_.all) {
      if (CommandInterface* driver = bodies_[static_cast<std::size_t>(teleop_.body)].steer) f(*driver);
      return;
    }
    for (const Body& b : bodies_)
      if (b.steer != nullptr) f(*b.steer);
  }

  // the details of the bodies pages have selected, as a JSON array, or "" (stepping thread)
  std::string detailsJson(const Environment& env, std::chrono::steady_clock::time_point now) {
    std::vector<int> bodies;
    {
      std::lock_guard lock(mutex_);
      bodies = stillWatched(now);
    }
    if (bodies.empty()) return {};
    std::string out = "[";
    for (const int b : bodies) {
      const PhysicNode& node = *nodes_[static_cast<std::size_t>(b)];
      const Artifact& a = node.artifact();
      const BodyState s = env.bodyState(node.bodyIndex());
      out += out.back() == '[' ? "" : ",";
      out += R"({"body":)" + std::to_string(b) + R"(,"name":)";
      appendString(out, names_[static_cast<std::size_t>(b)]);
      out += R"(,"v":[)";
      appendNumber(out, s.linear_velocity.x()), out += ',', appendNumber(out, s.linear_velocity.y()), out += ',';
      appendNumber(out, s.linear_velocity.z());
      out += R"(],"w":[)";
      appendNumber(out, s.angular_velocity.x()), out += ',', appendNumber(out, s.angular_velocity.y()), out += ',';
      appendNumber(out, s.angular_velocity.z());
      out += R"(],"command":)";
      const auto* commandable = dynamic_cast<const CommandInterface*>(a.driver());
      out += commandable != nullptr ? commandJson(commandable->currentCommand()) : "null";
      out += R"(,"sensors":[)";
      bool first = true;
      for (std::size_t k = 0; k < a.sensorCount(); ++k) {
        const std::string m = measurementJson(a.sensor(k).latest(), env);
        if (m.size() < 2) continue;
        out += first ? "" : ",";
        first = false;
        out += R"({"sensor":)";
        appendString(out, a.sensor(k).className());
        out += ',' + m.substr(1);
      }
      out += "]}";
    }
    return out + "]";
  }

  // the scene for a page: the models (render trees, each in its body's frame), the bodies with
  // their model, and what is fixed in the world
  std::string sceneJson(const Environment& env) const {
    // a render tree shared by a swarm's members: one model per body of it (its root, each joined part)
    std::map<std::pair<const RenderNodeSpec*, const PhysicNodeSpec*>, std::size_t> model_of;
    std::string models, bodies, world;
    bool first_world = true;
    MeshTable meshes;
    for (std::size_t b = 0; b < nodes_.size(); ++b) {
      const Artifact& a = nodes_[b]->artifact();
      std::size_t model = 0;
      const std::pair key{a.renderRoots().empty() ? nullptr : a.renderRoots().front().get(), &nodes_[b]->spec()};
      if (const auto it = model_of.find(key); it != model_of.end()) {
        model = it->second;
      } else {
        model = model_of.size();
        model_of[key] = model;
        std::string list;
        bool first = true;
        for (const auto& tree : a.renderRoots()) {
          const PhysicNode* follow = tree->follow.empty() ? nullptr : a.node(tree->follow);
          if (follow == nullptr) continue;  // drawn with the world below
          // the trees that move with this body, in its head's frame
          const RecordedBody* body = recordedBodyOf(recorded_, *follow);
          if (body == nullptr || body->node != nodes_[b]) continue;
          shapes(list, *tree, nodes_[b]->poseInBody().inverse() * follow->poseInBody(), first, meshes);
        }
        models += (models.empty() ? "" : ",") + std::string("[") + list + "]";
      }
      bodies += b == 0 ? "" : ",";
      bodies += "{\"name\":";
      appendString(bodies, names_[b]);
      bodies += ",\"model\":" + std::to_string(model) + "}";
    }
    for (std::size_t i = 0; i < env.artifactCount(); ++i) {
      const Artifact& a = env.artifact(i);
      const bool moving = std::find_if(nodes_.begin(), nodes_.end(), [&](const PhysicNode* n) {
                            return &n->artifact() == &a;
                          }) != nodes_.end();
      for (const auto& tree : a.renderRoots()) {
        const PhysicNode* follow = tree->follow.empty() ? nullptr : a.node(tree->follow);
        // (a moving artifact's trees move with its bodies, but those following a static node: an
        // arm's base bolted to the world)
        if (follow != nullptr && (follow->bodyIndex() >= 0 || (moving && !follow->isStatic()))) continue;
        shapes(world, *tree, follow != nullptr ? follow->pose() : a.placement(), first_world, meshes);
      }
    }
    std::string out = R"({"type":"scene","time":)";
    appendNumber(out, toSeconds(env.time()));
    if (playback_) {
      out += R"(,"replay":{"start":)";
      appendNumber(out, toSeconds(playback_->start()));
      out += R"(,"end":)";
      appendNumber(out, toSeconds(playback_->end()));
      out += '}';
    }
    out += R"(,"models":[)" + models + R"(],"bodies":[)" + bodies + R"(],"world":[)" + world + R"(],"meshes":)" +
           meshes.json() + "}";
    return out;
  }

  std::unique_ptr<viewer::Server> server_;
  RunControl* control_ = nullptr;
  std::vector<const PhysicNode*> nodes_;
  std::vector<RecordedBody> recorded_;  // nodes_ with their names, to find the body a node moves with
  std::vector<std::string> names_;
  struct Body {  // each node's body, the node's pose in it, and its driver if it takes velocity commands
    int index = -1;
    Pose in_body;
    bool at_body = true;
    CommandInterface* steer = nullptr;
  };
  std::vector<Body> bodies_;
  std::size_t steerable_ = 0;  // bodies with a steer
  std::vector<std::uint8_t> frame_;
  std::chrono::duration<double> period_{};
  viewer::FramePacer pacer_;  // when the run's next frame goes out
  std::chrono::steady_clock::time_point last_wall_;
  double last_sim_ = -1;
  std::uint32_t late_ = 0;
  bool begun_ = false;
  bool wait_ = false;                 // --view-wait: hold the run after its first step until a page says hello
  std::atomic<bool> waiting_{false};  // (set on the stepping thread, cleared by a page's hello)
  std::uint64_t built_ = 0;  // frames built on the stepping thread, and what they took
  double build_ms_sum_ = 0, build_ms_max_ = 0;
  // what pages asked (under mutex_; nodes_ is fixed once begun): the newest teleoperation command,
  // the bodies whose details they see
  static constexpr double kMaxSpeed = 20, kMaxYawRate = 10;
  static constexpr std::size_t kMaxWatched = 64;
  struct Teleop {
    int body = -1;  // -1 and not all: none
    bool all = false;
    Vec3 velocity = Vec3::Zero();
    double yaw_rate = 0;
    std::chrono::steady_clock::time_point received;
    bool fresh = false;
    double sent = -1;  // when the page sent it, on the page's clock (ms), or -1
    double page = 0;   // the page's number for itself
  };
  viewer::CommandEcho used_;  // the newest command a step used, for the next frame
  std::mutex mutex_;
  Teleop teleop_;
  std::map<int, std::chrono::steady_clock::time_point> watched_;
  bool details_asked_ = false;  // a body newly watched: its details at once (a paused replay sends a frame a second)
  std::unique_ptr<viewer::ReplayDetails> replay_details_;  // a recording's robots as recorded
  std::vector<double> delays_ms_;  // from a command's arrival to the step that used it
  std::uint64_t teleop_stops_ = 0;
  std::string url_;
  // replaying: the recording, its clock (under mutex_) and the thread that plays it
  std::unique_ptr<Recording> recording_;
  std::unique_ptr<viewer::Playback> playback_;
  std::thread player_;
  std::vector<std::uint8_t> play_frame_;  // (the player's own)
  std::condition_variable playing_cv_;
  bool stop_playing_ = false;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_EXTENSION(ssx::plugins::Viewer, "viewer"));
