#include "recording_commands.hpp"

#include <ssx/ssx.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

namespace ssx::cli {

namespace fs = std::filesystem;

namespace {

std::string seconds(Nanoseconds t) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f s", toSeconds(t));
  return text;
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char e[8];
      std::snprintf(e, sizeof e, "\\u%04x", c);
      out += e;
      continue;
    }
    out += c;
  }
  return out + "\"";
}

// the recorded scene, built to draw or to step: plugins from the recording's plugin directories
// and the ones given; the scene's own camera outputs left out (a replay writes only what it is
// asked to). Drawing leaves the extensions out (no logger writes, no bridge connects); a
// re-simulation keeps them (a saved state holds theirs), their relative outputs going into
// ssx-out/<scene>-resimulated/ rather than over the recorded run's
Scene buildRecorded(const Recording& r, const ReplayArgs& args, bool draw, int* status) {
  // said before anything is built: a scene of another version may read differently, and a
  // re-simulation compares bits that another version's physics need not give
  if (r.version() != SSX_VERSION_STRING)
    std::cerr << "ssx replay: warning: " << args.file << " was recorded by ssx " << r.version() << ", this is ssx "
              << SSX_VERSION_STRING << ": the scene may read differently and a re-simulation may not match\n";
  SceneOptions options;
  options.plugin_path = pluginPath(args.plugin_path);
  options.extensions = !draw;
  if (!draw) options.output_directory = fs::path("ssx-out") / (fs::path(r.sceneLabel()).stem().string() + "-resimulated");
  for (const std::string& s : args.set) {
    // PATH=VALUE, the path's own '=' (name[attribute=value]) before its '@'
    const auto at = s.find('@');
    const auto eq = at == std::string::npos ? std::string::npos : s.find('=', at);
    if (eq == std::string::npos || eq == 0) {
      std::cerr << "ssx: error: --set " << s << ": write PATH=VALUE (e.g. swarm[name=q{i}]/driver@position_kp=4)\n";
      *status = kExitBadInput;
      return {};
    }
    options.overrides.push_back({s.substr(0, eq), s.substr(eq + 1), SourceLocation{"--set", 0}});
  }
  const bool pictures = draw && args.view < 0;  // (a page draws for itself)
  if (pictures) options.render_engine = "osmesa";
  try {
    SceneModel model = parseSceneString(r.sceneXml(), r.sceneLabel().empty() ? "recorded scene" : r.sceneLabel(),
                                        fs::current_path(), options);
    for (CameraSpec& c : model.settings.render.cameras) {
      c.snapshot.clear();
      c.video.clear();
      c.frames_dir.clear();
    }
    // the outputs asked for, on the first camera: the follow camera, the scene's first, or one
    // framing every robot
    if (pictures && model.settings.render.cameras.empty() && args.follow.empty()) {
      CameraSpec all;
      all.name = "replay";
      all.frame_scene = true;
      model.settings.render.cameras.push_back(all);
    }
    if (pictures && !args.follow.empty()) {
      CameraSpec chase;
      chase.name = "follow";
      chase.follow = args.follow;
      chase.position = Vec3(-3, 0, 1.5);
      chase.look_at = Vec3::Zero();
      model.settings.render.cameras.insert(model.settings.render.cameras.begin(), chase);
    }
    if (pictures) {
      CameraSpec& first = model.settings.render.cameras.front();
      first.snapshot = args.snapshot;
      first.video = args.video;
      first.frames_dir = args.frames;
    }
    // frames at the recording's rate
    if (pictures && r.times().size() > 1) {
      const Nanoseconds interval = r.times()[1] - r.times()[0];
      if (interval > 0) model.settings.render.rate_hz = 1.0 / toSeconds(interval);
    }
    Scene scene = buildScene(model, options);
    return scene;
  } catch (const SceneError& e) {
    std::cerr << e.what() << "\nssx replay: the recorded scene (recorded by ssx " << r.version()
              << ") was not built: the lines above say why (a recording names its artifact files and plugin "
                 "directories where they were; --plugin-path adds others)\n";
    *status = kExitBadInput;
    return {};
  }
}

// the root node each recorded name stands for ("artifact", or "artifact/node" for an artifact's
// later roots), in the recording's order; empty, with a message, when one is missing
std::vector<const PhysicNode*> recordedNodes(const Environment& env, const Recording& r) {
  std::vector<const PhysicNode*> nodes;
  for (const std::string& name : r.names()) {
    const auto slash = name.find('/');
    const Artifact* a = env.findArtifact(name.substr(0, slash));
    const PhysicNode* node = a == nullptr ? nullptr : slash == std::string::npos ? &a->root() : a->node(name.substr(slash + 1));
    if (node == nullptr || node->bodyIndex() < 0) {
      std::cerr << "ssx: error: " << r.names().size() << " bodies recorded, but the recorded scene has no body '" << name
                << "' (a recording of another version?)\n";
      return {};
    }
    nodes.push_back(node);
  }
  return nodes;
}

int draw(const Recording& r, const ReplayArgs& args) {
  if (args.snapshot.empty() && args.video.empty() && args.frames.empty()) {
    std::cerr << "ssx: error: ssx replay draws into --snapshot, --video or --frames (or re-simulates: "
                 "--resimulate-from)\n";
    return kExitBadInput;
  }
  const Nanoseconds from = toNanoseconds(args.from);
  const Nanoseconds to = args.to >= 0 ? toNanoseconds(args.to) : std::numeric_limits<Nanoseconds>::max();
  // the samples drawn, one per frame: every one at --speed 1; at another speed the frames keep the
  // recording's rate and each shows the sample at or before its time (repeated in slow motion).
  // Made one at a time (a slow replay of a long recording is many frames); the times ascend
  // (Recording checks it), so the frames end
  const auto& times = r.times();
  const auto first = std::lower_bound(times.begin(), times.end(), from);
  const Nanoseconds end = times.empty() ? 0 : std::min(to, times.back());
  if (first == times.end() || *first > end) {
    std::cerr << "ssx: error: nothing to draw from " << seconds(from) << (args.to >= 0 ? " to " + seconds(to) : std::string())
              << ": the recording's samples run from " << (times.empty() ? std::string("(none)") : seconds(times.front()))
              << " to " << (times.empty() ? std::string("(none)") : seconds(times.back())) << '\n';
    return kExitBadInput;
  }
  const double frame_step = times.size() > 1 ? toSeconds(times[1] - times[0]) * args.speed : 0;
  std::int64_t frame = 0;
  // the next frame's sample, or false at the end
  auto nextFrame = [&](std::size_t& k) {
    if (args.speed == 1 || times.size() < 2) {
      const auto it = first + frame;
      if (it == times.end() || *it > end) return false;
      k = static_cast<std::size_t>(it - times.begin());
    } else {
      const Nanoseconds t = *first + toNanoseconds(static_cast<double>(frame) * frame_step);
      if (t > end) return false;
      k = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin() - 1);
    }
    ++frame;
    return true;
  };
  int status = 0;
  Scene scene = buildRecorded(r, args, true, &status);
  if (status != 0) return status;
  Environment& env = *scene.environment;
  env.start();
  const std::vector<const PhysicNode*> nodes = recordedNodes(env, r);
  if (nodes.size() != r.names().size()) return kExitBadInput;
  std::int64_t drawn = 0;
  std::vector<CameraSpec> cameras;
  // trails: a dot at each recorded position of the last --trails seconds, a tenth of the robot's
  // width across, in the robot's colour (the first shape it draws)
  std::vector<RenderNodeSpec> dots(nodes.size());
  std::vector<RenderNode> overlay;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    double reach = 0;
    dots[i].color = {1.0f, 0.6f, 0.1f, 1.0f};
    bool coloured = false;
    for (const auto& tree : nodes[i]->artifact().renderRoots()) {
      auto visit = [&](auto& self, const RenderNodeSpec& n, const Vec3& at) -> void {
        const Vec3 here = at + n.pose.position;
        if (n.primitive != RenderNodeSpec::Primitive::None) {
          if (!coloured) dots[i].color = n.color, coloured = true;
          const double half = n.primitive == RenderNodeSpec::Primitive::Box ? 0.5 * n.size.maxCoeff()
                              : n.primitive == RenderNodeSpec::Primitive::Mesh && n.mesh != nullptr
                                  ? n.mesh->min.cwiseAbs().cwiseMax(n.mesh->max.cwiseAbs()).norm()
                                  : n.radius;
          reach = std::max(reach, here.norm() + half);
        }
        for (const auto& c : n.children) self(self, c, here);
      };
      visit(visit, *tree, Vec3::Zero());
    }
    dots[i].primitive = RenderNodeSpec::Primitive::Sphere;
    dots[i].radius = std::max(0.005, 0.1 * reach);
  }
  const Nanoseconds trail = toNanoseconds(args.trails);
  try {
    for (std::size_t k = 0; nextFrame(k);) {
      const Nanoseconds t = times[k];
      overlay.clear();
      for (std::size_t j = k; args.trails > 0 && j-- > 0 && times[j] >= t - trail;) {
        const std::vector<float> past = r.positions(j);
        for (std::size_t i = 0; i < nodes.size(); ++i)
          overlay.push_back({&dots[i], nullptr, Pose{Vec3(past[3 * i], past[3 * i + 1], past[3 * i + 2]), Quat::Identity()}});
      }
      const std::vector<float> p = r.positions(k), q = r.orientations(k);
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        // the recorded pose is the root node's: its body's centre-of-mass frame from it
        const Pose node{Vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]),
                        Quat(q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]).normalized()};
        BodyState s = env.bodyState(nodes[i]->bodyIndex());
        s.pose = node * nodes[i]->poseInBody().inverse();
        s.linear_velocity.setZero();
        s.angular_velocity.setZero();
        env.setBodyState(nodes[i]->bodyIndex(), s);
      }
      env.drawFrame(t, overlay);
      ++drawn;
    }
    cameras = env.cameras();
    env.stop();
  } catch (const std::exception& e) {
    std::cerr << "ssx: error: " << e.what() << '\n';
    return kExitRunFailure;
  }
  std::cout << "replayed " << drawn << (args.speed == 1 ? " samples" : " frames") << " of " << nodes.size() << " bodies";
  if (drawn > 0) std::cout << " (" << seconds(std::max(from, r.times().front())) << " to " << seconds(std::min(to, r.times().back())) << ")";
  std::cout << '\n';
  for (const auto& c : cameras) {
    if (!c.snapshot.empty() && fs::exists(c.snapshot)) std::cout << "camera " << c.name << ": snapshot " << c.snapshot.string() << '\n';
    if (!c.video.empty() && fs::exists(c.video)) std::cout << "camera " << c.name << ": video " << c.video.string() << '\n';
    if (!c.frames_dir.empty()) std::cout << "camera " << c.name << ": " << drawn << " frames in " << c.frames_dir.string() << '\n';
  }
  return 0;
}

// --view: the recorded scene built, and the viewer extension playing the recording on a page (its
// own thread, its own clock: viewer.cpp) until SIGINT or SIGTERM
std::atomic<int> g_view_signal{0};

int view(const Recording& r, const ReplayArgs& args) {
  int status = 0;
  Scene scene = buildRecorded(r, args, true, &status);
  if (status != 0) return status;
  Environment& env = *scene.environment;
  try {
    addViewer(env, args.view, args.view_bind, args.file);
    env.start();
  } catch (const std::exception& e) {
    std::cerr << "ssx: error: --view: " << e.what() << '\n';
    return kExitBadInput;
  }
  std::signal(SIGINT, [](int sig) { g_view_signal = sig; });
  std::signal(SIGTERM, [](int sig) { g_view_signal = sig; });
  try {
    env.step(1);  // the bodies exist from the first step on: the viewer takes them, and the scene, then
    std::cerr << "ssx replay: playing " << args.file << " (" << r.names().size() << " bodies, " << seconds(r.times().front())
              << " to " << seconds(r.times().back()) << ") on the page until Ctrl-C\n";
    while (g_view_signal == 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    env.stop();
  } catch (const std::exception& e) {
    std::cerr << "ssx: error: " << e.what() << '\n';
    return kExitRunFailure;
  }
  return 128 + g_view_signal;
}

int resimulate(const Recording& r, const ReplayArgs& args) {
  int status = 0;
  Scene scene = buildRecorded(r, args, false, &status);
  if (status != 0) return status;
  Environment& env = *scene.environment;
  if (!args.record.empty()) {
    scene.files.addInput(args.file);  // the recording replayed is never written over
    const std::string problem = scene.files.claimOutput(args.record, "--record", true);
    if (!problem.empty()) {
      std::cerr << "ssx: error: " << problem << '\n';
      return kExitBadInput;
    }
  }
  // the scene's own outputs go into ssx-out/<scene>-resimulated/, made now that every check passed
  const fs::path out_dir = fs::path("ssx-out") / (fs::path(r.sceneLabel()).stem().string() + "-resimulated");
  for (const fs::path& p : scene.files.outputs()) {
    const auto rel = p.lexically_relative(out_dir);
    if (!rel.empty() && *rel.begin() != "..") {
      std::error_code ec;
      fs::create_directories(out_dir, ec);
      break;
    }
  }
  Nanoseconds at = 0;
  const Nanoseconds from = toNanoseconds(args.resimulate_from);
  std::unique_ptr<Recorder> recorder;
  try {
    // the saved state at or before the time asked for; before the first one, the first
    const std::vector<Nanoseconds> times = r.stateTimes();
    const std::vector<std::byte> state =
        r.stateAtOrBefore(!times.empty() && from < times.front() ? times.front() : from, &at);
    env.checkState(state);
    env.start();
    env.restoreState(state);
    // the recorded run's switches of physics engine from there on, at their times (a state saved
    // at a switch's time was saved before it: states are taken at the end of a step)
    for (const ssx::PhysicsSwitch& x : r.physicsSwitches())
      if (x.time >= at) env.switchPhysicsAt(x.time, x.to);
  } catch (const std::exception& e) {
    std::cerr << "ssx: error: " << e.what() << '\n';
    return kExitBadInput;
  }
  // step, comparing each recorded sample on the way: from the saved state to the time asked for
  // (as recorded, but for --set), then on from there, recorded (--record) and for --duration
  const std::vector<const PhysicNode*> nodes = recordedNodes(env, r);
  if (nodes.size() != r.names().size()) return kExitBadInput;
  std::size_t compared = 0, equal = 0;
  double largest = 0;
  std::string largest_at, first_difference;
  std::size_t k = 0;
  while (k < r.times().size() && r.times()[k] <= at) ++k;
  auto stepTo = [&](Nanoseconds end) {
    while (env.time() < end) {
      env.step();
      if (k < r.times().size() && r.times()[k] == env.time()) {
        const std::vector<float> recorded = r.positions(k);
        bool same = true;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
          const std::string& name = r.names()[i];
          const Vec3 p = nodes[i]->pose().position;
          double d = 0;
          for (int c = 0; c < 3; ++c) {
            const auto now = static_cast<float>(p[c]);
            same = same && now == recorded[3 * i + static_cast<std::size_t>(c)];
            d = std::max(d, std::abs(static_cast<double>(now) - recorded[3 * i + static_cast<std::size_t>(c)]));
          }
          if (d > 0 && first_difference.empty()) first_difference = seconds(r.times()[k]) + " (" + name + ")";
          if (d > largest) {
            largest = d;
            largest_at = name + " at " + seconds(r.times()[k]);
          }
        }
        ++compared;
        equal += same ? 1 : 0;
        ++k;
      }
    }
  };
  Nanoseconds start = at, end = at;
  try {
    stepTo(from);
    start = env.time();  // the time asked for (to the step)
    end = args.duration > 0 ? start + toNanoseconds(args.duration) : std::max(start, r.times().empty() ? start : r.times().back());
    if (!args.record.empty()) {
      RecordOptions o;
      o.file = args.record;
      o.scene_xml = scene.model->toXml();
      o.scene_label = r.sceneLabel();
      recorder = std::make_unique<Recorder>(env, o);
    }
    stepTo(end);
    if (recorder) std::cout << recorder->finish().str(args.record) << '\n';
    env.stop();
  } catch (const std::exception& e) {
    std::cerr << "ssx: error: " << e.what() << '\n';
    return kExitRunFailure;
  }
  std::cout << "re-simulated from " << seconds(start) << " (stepped from the saved state at " << seconds(at)
            << (args.set.empty() || start == at ? "" : ", with the --set values from there") << ") to " << seconds(end)
            << ": " << compared << " recorded samples compared, ";
  if (equal == compared)
    std::cout << "every one equal to the recording bit for bit\n";
  else
    std::cout << equal << " equal; the first difference at " << first_difference << ", the largest " << largest
              << " m (" << largest_at << ")\n";
  return 0;
}

}  // namespace

int commandInspect(const InspectArgs& args) {
  try {
    const Recording r(args.file);
    if (!args.complete.empty()) {
      // the one output check: never over the recording read, a symbolic link, a FIFO or a device
      RunFiles files;
      files.addInput(args.file);
      if (const std::string problem = files.claimOutput(args.complete, "--complete", true); !problem.empty()) {
        std::cerr << "ssx: error: " << problem << '\n';
        return kExitBadInput;
      }
      completeRecording(args.file, args.complete);
    }
    const auto states = r.stateTimes();
    if (args.json) {
      std::ostringstream o;
      o << "{\"file\":" << jsonString(args.file) << ",\"complete\":" << (r.complete() ? "true" : "false")
        << ",\"bytes\":" << r.size() << ",\"version\":" << jsonString(r.version()) << ",\"seed\":" << r.seed()
        << ",\"scene\":" << jsonString(r.sceneLabel()) << ",\"bodies\":" << r.names().size() << ",\"names\":[";
      for (std::size_t i = 0; i < r.names().size(); ++i) o << (i ? "," : "") << jsonString(r.names()[i]);
      o << "],\"channels\":{";
      bool first = true;
      for (const auto& [topic, count] : r.channels()) {
        o << (first ? "" : ",") << jsonString(topic) << ":" << count;
        first = false;
      }
      o << "},\"first_time_ns\":" << (r.times().empty() ? 0 : r.times().front())
        << ",\"last_time_ns\":" << (r.times().empty() ? 0 : r.times().back()) << ",\"states_ns\":[";
      for (std::size_t i = 0; i < states.size(); ++i) o << (i ? "," : "") << states[i];
      o << "],\"physics_switches\":[";
      const std::vector<PhysicsSwitch> switches = r.physicsSwitches();
      for (std::size_t i = 0; i < switches.size(); ++i) {
        const PhysicsSwitch& x = switches[i];
        o << (i ? "," : "") << "{\"time_ns\":" << x.time << ",\"from\":" << jsonString(x.from) << ",\"to\":" << jsonString(x.to) << "}";
      }
      o << "]}";
      std::cout << o.str() << '\n';
      return 0;
    }
    std::cout << args.file << ": " << (r.complete() ? "complete" : "cut short (no summary: ssx inspect --complete FILE writes a complete copy)")
              << ", " << r.size() << " bytes, recorded by ssx " << r.version() << ", scene " << r.sceneLabel()
              << ", seed " << r.seed() << '\n';
    std::cout << r.names().size() << " bodies, " << r.times().size() << " pose samples";
    if (!r.times().empty()) std::cout << " from " << seconds(r.times().front()) << " to " << seconds(r.times().back());
    std::cout << '\n';
    for (const auto& [topic, count] : r.channels()) std::cout << "channel " << topic << ": " << count << " messages\n";
    std::cout << "saved states: " << states.size();
    for (std::size_t i = 0; i < states.size(); ++i) std::cout << (i ? ", " : " at ") << seconds(states[i]);
    std::cout << '\n';
    for (const PhysicsSwitch& x : r.physicsSwitches())
      std::cout << "physics: " << x.from << " to " << x.to << " at " << seconds(x.time) << '\n';
    if (!args.complete.empty()) std::cout << "complete copy written to " << args.complete << '\n';
  } catch (const std::exception& e) {
    std::cerr << "ssx: error: " << e.what() << '\n';
    return kExitBadInput;
  }
  return 0;
}

int commandReplay(const ReplayArgs& args) {
  // never written over: the recording itself (by any name: a hard or symbolic link is the same
  // file), and no output over another
  {
    RunFiles files;
    files.addInput(args.file);
    for (const auto& [path, what] : {std::pair{args.snapshot, "--snapshot"}, std::pair{args.video, "--video"},
                                     std::pair{args.record, "--record"}}) {
      if (path.empty()) continue;
      std::string problem = files.claimOutput(path, what, std::string(what) == "--record");
      if (problem.find("which this run reads") != std::string::npos)
        problem = std::string(what) + " " + path + " would write over the recording being replayed: name another";
      if (!problem.empty()) {
        std::cerr << "ssx: error: " << problem << '\n';
        return kExitBadInput;
      }
    }
    if (!args.frames.empty())
      if (const std::string problem = files.claimOutputDirectory(args.frames, "--frames"); !problem.empty()) {
        std::cerr << "ssx: error: " << problem << '\n';
        return kExitBadInput;
      }
  }
  try {
    const Recording r(args.file);
    if (args.view >= 0) return view(r, args);
    return args.resimulate_from >= 0 ? resimulate(r, args) : draw(r, args);
  } catch (const std::exception& e) {
    std::cerr << "ssx: error: " << e.what() << '\n';
    return kExitBadInput;
  }
}

}  // namespace ssx::cli
