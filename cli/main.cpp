// ssx: the command-line client. run, validate, sweep; plugins in plugins_command.cpp.
//
// Exit status: 0 success, 2 bad input (scene, arguments, plugins), 1 failure while running.
#include "common.hpp"
#include "command_line.hpp"
#include "number_options.hpp"
#include "plugins_command.hpp"
#include "recording_commands.hpp"
#include "sweep.hpp"

#include <ssx/ssx.hpp>

#include <CLI/CLI.hpp>

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cerrno>
#include <cstdlib>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <optional>
#include <limits>
#include <new>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace ssx::cli;

namespace fs = std::filesystem;


std::atomic<bool> g_stop{false};

std::atomic<int> g_signal{0};  // the signal that stopped the run, if one did
void onSignal(int sig) {
  g_signal = sig;
  g_stop = true;
}


void printWarnings(const ssx::Scene& scene) {
  for (const auto& w : scene.warnings) std::cerr << w.str() << '\n';
}

// a one-line progress display on stderr, redrawn at most ten times a second
class Progress {
 public:
  Progress(bool enabled, std::int64_t total_steps) : enabled_(enabled), total_(total_steps) {}
  void update(const ssx::Environment& env) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const double t = ssx::toSeconds(env.time());
    if (total_ > 0) {
      const double f = static_cast<double>(env.stepCount()) / static_cast<double>(total_);
      const int width = 30;
      const int filled = static_cast<int>(f * width);
      std::fprintf(stderr, "\r[%.*s%*s] %5.1f%%  t = %.2f s ", filled, "##############################", width - filled,
                   "", 100.0 * f, t);
    } else {
      std::fprintf(stderr, "\rt = %.2f s (Ctrl-C to stop) ", t);
    }
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) std::fprintf(stderr, "\r%60s\r", "");
  }

 private:
  bool enabled_;
  std::int64_t total_;
  std::chrono::steady_clock::time_point last_{};
};

// a scene's problems by file (in the order the files were first named) and line within each
void printSorted(const ssx::SceneError& e) {
  std::vector<ssx::Diagnostic> d = e.diagnostics();
  std::vector<std::string> files;
  const auto rank = [&files](const std::string& file) {
    const auto it = std::find(files.begin(), files.end(), file);
    return static_cast<std::size_t>(it - files.begin());
  };
  for (const auto& x : d)
    if (std::find(files.begin(), files.end(), x.where.file) == files.end()) files.push_back(x.where.file);
  std::stable_sort(d.begin(), d.end(), [&](const ssx::Diagnostic& a, const ssx::Diagnostic& b) {
    const auto ra = rank(a.where.file), rb = rank(b.where.file);
    return ra != rb ? ra < rb : a.where.line < b.where.line;
  });
  std::size_t errors = 0;
  for (const auto& x : d) {
    std::cerr << x.str() << '\n';
    errors += x.severity == ssx::Diagnostic::Severity::Error ? 1 : 0;
  }
  std::cerr << errors << " error(s); nothing was run\n";
}

std::string formatFactor(double f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", f);
  return buf;
}

// "physics: ode, then bullet from 1.5 s, then ode from 3 s"
std::string physicsSwitchesLine(const ssx::Environment& env) {
  const auto& switches = env.physicsSwitches();
  std::string line = "physics: " + switches.front().from;
  for (const auto& s : switches) {
    char at[48];
    std::snprintf(at, sizeof at, "%.6g s", ssx::toSeconds(s.time));
    line += ", then " + s.to + " from " + at;
  }
  return line;
}

// a saved state: a regular file of at most max_bytes (ssx::readInputFile)
std::vector<std::byte> readFile(const std::string& path, std::uintmax_t max_bytes) {
  std::string text;
  try {
    text = ssx::readInputFile(path, max_bytes);
  } catch (const ssx::ConfigError& e) {
    throw std::runtime_error(e.detail());
  }
  std::vector<std::byte> out(text.size());
  std::memcpy(out.data(), text.data(), text.size());
  return out;
}


// written beside the target and renamed over it: a failed write never leaves a short file
void writeFileAtomically(const std::string& path, const std::vector<std::byte>& bytes) {
  const std::string partial = path + ".partial";
  std::FILE* f = ssx::openOutputFile(partial);  // (locked: a second run saving to the same file is refused)
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  const bool closed = std::fclose(f) == 0;
  if (!written || !closed) {
    std::remove(partial.c_str());
    throw std::runtime_error("writing '" + partial + "' failed (disk full?)");
  }
  if (std::rename(partial.c_str(), path.c_str()) != 0) {
    std::remove(partial.c_str());
    throw std::runtime_error("cannot rename '" + partial + "' to '" + path + "': " + std::strerror(errno));
  }
}

int commandRun(const RunArgs& args, bool realtime_given) {
  // a real-time priority this process may not take is refused before anything is loaded or opened
  if (args.rt_priority > 0) {
    const std::string problem = ssx::realtimePriorityProblem(args.rt_priority);
    if (!problem.empty()) {
      std::cerr << "ssx: error: --rt-priority " << args.rt_priority << ": " << problem << '\n';
      return kExitBadInput;
    }
  }
  ssx::SceneOptions options;
  options.plugin_path = pluginPath(args.plugin_path);
  if (args.threads >= 0) options.threads = args.threads;
  options.seed = args.seed;
  if (!args.render.empty()) options.render_engine = args.render;
  if (!args.physics.empty()) options.physics_engine = args.physics;
  options.snapshot = args.snapshot;
  options.video = args.video;
  options.frames_dir = args.frames;
  options.allow_special_outputs = args.allow_special_outputs;
  options.max_input_bytes = maxInputBytes(args.max_input_mb);
  // the scene's own outputs into a directory of this run, never the working directory unasked
  const fs::path out_dir = outputDirectory(args.scene, args.out);
  options.output_directory = out_dir;
  // settings of this process for drawing with Mesa's llvmpipe (the library leaves the process
  // alone; a program that embeds it chooses these itself, see docs/library.md, Rendering):
  // - llvmpipe's own rasteriser threads cost more than they give at these image sizes and would
  //   compete with the simulation's workers (a user's LP_NUM_THREADS still wins);
  // - llvmpipe allocates and frees large blocks every frame; with glibc's default trim threshold
  //   (128 KiB) each free hands the heap top back to the kernel and the next frame faults it in
  //   again: 2-3x the frame time (measured, 640 x 480: 13.3 -> 4.6 ms with 70 robots, 77 -> 25 ms
  //   with 1,000). Up to 256 MiB of free heap is kept instead.
  setenv("LP_NUM_THREADS", "0", 0);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  ssx::Scene scene;
  try {
    scene = ssx::loadScene(args.scene, options);
  } catch (const ssx::SceneError& e) {
    printSorted(e);
    return kExitBadInput;
  }
  printWarnings(scene);
  ssx::Environment& env = *scene.environment;
  if (args.view >= 0) {
    try {
      addViewer(env, args.view, args.view_bind, {}, args.view_wait);
    } catch (const std::exception& e) {
      std::cerr << "ssx: error: --view: " << e.what() << '\n';
      return kExitBadInput;
    }
  }
  if (args.foxglove >= 0) {
    try {
      addFoxglove(env, args.foxglove, args.foxglove_bind);
    } catch (const std::exception& e) {
      std::cerr << "ssx: error: --foxglove: " << e.what() << '\n';
      return kExitBadInput;
    }
  }
  if (args.frames_from > 0 || args.frames_until >= 0) {
    // the scene cameras' frames in a window of simulated time: opened at its start, finished at its end
    ssx::RenderSettings render = env.settings().render;
    if (render.cameras.empty()) {
      std::cerr << "ssx: error: --frames-from/--frames-until: the scene draws no frames: give --video, --frames or "
                   "--snapshot, or a <camera> in the scene's <render>\n";
      return kExitBadInput;
    }
    render.from = ssx::toNanoseconds(args.frames_from);
    render.until = args.frames_until < 0 ? -1 : ssx::toNanoseconds(args.frames_until);
    env.attachRenderer(std::move(render));  // (before start: what the run starts with)
  }
  // this command's own files, with the scene's: nothing is written over what the run reads or
  // writes already, before anything starts
  {
    if (!args.load_state.empty()) scene.files.addInput(args.load_state);
    std::string problem;
    if (!args.save_state.empty()) problem = scene.files.claimOutput(args.save_state, "--save-state", true);
    if (problem.empty() && !args.stats_csv.empty()) problem = scene.files.claimOutput(args.stats_csv, "--stats-csv");
    if (problem.empty() && !args.record.empty()) problem = scene.files.claimOutput(args.record, "--record", true);
    if (!problem.empty()) {
      std::cerr << "ssx: error: " << problem << '\n';
      return kExitBadInput;
    }
  }

  ssx::RunOptions run = scene.run;
  run.mode = args.fast ? ssx::RunOptions::Mode::Fast : ssx::RunOptions::Mode::RealTime;
  if (realtime_given) run.realtime_factor = args.realtime;
  run.realtime_priority = args.rt_priority;
  if (args.steps >= 0) {
    run.steps = args.steps;
  } else {
    if (args.duration_given && (!std::isfinite(args.duration) || !(ssx::toNanoseconds(args.duration) > 0))) {
      std::cerr << "ssx: error: --duration " << args.duration
                << ": not a number of seconds of at least a nanosecond (the run would have no end)\n";
      return kExitBadInput;
    }
    const ssx::Nanoseconds duration =
        args.duration_given ? ssx::toNanoseconds(args.duration) : scene.duration.value_or(-1);
    if (duration > 0) run.steps = (duration + env.timestep() - 1) / env.timestep();
  }
  run.stop = &g_stop;
  Progress progress(!args.quiet && isatty(STDERR_FILENO) == 1, run.steps);
  // what happens to the robots, sampled every 10th step; a robot that crashes is said at once
  ssx::FlightRecorder flights;
  std::int64_t crashes_said = 0;
  run.on_step = [&progress, &flights, &crashes_said](const ssx::Environment& e) {
    progress.update(e);
    if (e.stepCount() % 10 != 0) return;
    flights.observe(e);
    const ssx::FlightSummary now = flights.summary();
    if (now.crashed > crashes_said) {
      progress.finish();
      std::cerr << "ssx: warning: t = " << ssx::toSeconds(e.time()) << " s: " << now.crashed
                << " robot(s) crashed (tilted over, or down after an impact): " << (now.crashed_names.empty() ? "" : now.crashed_names.back())
                << (now.crashed > 1 ? " and others" : "") << '\n';
    }
    crashes_said = now.crashed;
  };

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  // a video pipe whose ffmpeg died reports an error instead of killing the process
  std::signal(SIGPIPE, SIG_IGN);
  // a saved state to continue from is read and checked before anything starts
  std::vector<std::byte> loaded;
  if (!args.load_state.empty()) {
    try {
      loaded = readFile(args.load_state, maxInputBytes(args.max_input_mb));
      env.checkState(loaded);
    } catch (const std::exception& e) {
      std::cerr << "ssx: error: --load-state " << args.load_state << ": " << e.what() << '\n';
      return kExitBadInput;
    }
  }
  // every check passed: the output directory may be made now (when anything goes into it)
  const bool writes_into_out = std::any_of(scene.files.outputs().begin(), scene.files.outputs().end(),
                                           [&out_dir](const fs::path& p) {
                                             const auto rel = p.lexically_relative(out_dir);
                                             return !rel.empty() && *rel.begin() != "..";
                                           });
  if (writes_into_out) {
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    if (ec) {
      std::cerr << "ssx: error: --out " << out_dir.string() << ": cannot make the directory: " << ec.message() << '\n';
      return kExitBadInput;
    }
  }
  int status = 0;
  ssx::TimingSummary summary;
  // the recording: created now that every check passed; a real-time run drops samples rather than
  // wait for the writer, a fast one waits
  std::unique_ptr<ssx::Recorder> recorder;
  if (!args.record.empty()) {
    try {
      ssx::RecordOptions record;
      record.file = args.record;
      record.rate_hz = args.record_rate;
      record.state_every_s = args.record_states;
      record.drop_when_behind = !args.fast;
      if (!args.record_channels.empty()) {
        const auto has = [&](const char* name) {
          return std::find(args.record_channels.begin(), args.record_channels.end(), name) != args.record_channels.end();
        };
        record.foxglove = has("foxglove");
        record.timing = has("timing");
        record.sensors = has("sensors");
        record.commands = has("commands");
        record.contacts = has("contacts");
      }
      record.scene_xml = scene.model->toXml();
      record.scene_label = fs::path(args.scene).filename().string();
      recorder = std::make_unique<ssx::Recorder>(env, std::move(record));
    } catch (const std::exception& e) {
      std::cerr << "ssx: error: --record " << args.record << ": " << e.what() << '\n';
      return kExitBadInput;
    }
  }
  try {
    env.start();
    if (!loaded.empty()) env.restoreState(loaded);
    if (recorder) recorder->prepare();  // (the first saved state then costs a step what the later ones do)
    for (const std::string& spec : args.switch_physics) {
      const auto [at, engine] = *parseSwitch(spec);
      env.switchPhysicsAt(ssx::toNanoseconds(at), engine);
    }
    if (!args.quiet)
      std::cerr << "ssx: " << scene.file.string() << ": " << env.artifactCount() << " artifacts, " << env.threadCount()
                << " thread(s), timestep " << ssx::toSeconds(env.timestep()) * 1e3 << " ms, "
                << (args.fast ? std::string("as fast as possible") : "real time x" + formatFactor(run.realtime_factor))
                << '\n';
    summary = env.run(run);
  } catch (const ssx::ConfigError& e) {
    progress.finish();
    std::cerr << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    progress.finish();
    std::cerr << "ssx: error: " << e.what() << '\n';
    status = kExitRunFailure;
  }
  progress.finish();
  if (g_stop) std::cerr << "ssx: interrupted at t = " << ssx::toSeconds(env.time()) << " s\n";
  if (!args.save_state.empty()) {
    try {
      writeFileAtomically(args.save_state, env.saveState());
      if (!args.quiet) std::cerr << "ssx: state at t = " << ssx::toSeconds(env.time()) << " s saved to " << args.save_state << '\n';
    } catch (const std::exception& e) {
      std::cerr << "ssx: error: --save-state " << args.save_state << ": " << e.what() << '\n';
      status = kExitRunFailure;
    }
  }
  std::string recorded;
  if (recorder) {
    try {
      recorded = recorder->finish().str(args.record);
    } catch (const std::exception& e) {
      std::cerr << "ssx: error: --record: " << e.what() << '\n';
      status = kExitRunFailure;
    }
  }
  // (the settings' cameras: those whose frames had a window are closed by now)
  const std::vector<ssx::CameraSpec> cameras = env.settings().render.cameras;
  if (env.state() == ssx::Environment::State::Running) flights.observe(env);  // the end states
  // stop cleanly: plugins destroyed, engines stopped, extensions shut down (files closed)
  try {
    env.stop();
  } catch (const std::exception& e) {
    std::cerr << "ssx: error while stopping: " << e.what() << '\n';
    status = kExitRunFailure;
  }
  if (status == 0) {
    if (!args.quiet) std::cout << summary.str() << '\n' << flights.summary().str() << '\n';
    if (!args.quiet && !env.physicsSwitches().empty()) std::cout << physicsSwitchesLine(env) << '\n';
    if (!args.quiet && !recorded.empty()) std::cout << recorded << '\n';
  }
  // where the pictures went
  if (!args.quiet && env.frameCount() > 0) {
    for (const auto& c : cameras) {
      if (!c.snapshot.empty() && fs::exists(c.snapshot))
        std::cout << "camera " << c.name << ": snapshot " << c.snapshot.string() << '\n';
      if (!c.video.empty() && fs::exists(c.video))
        std::cout << "camera " << c.name << ": video " << c.video.string() << '\n';
      if (!c.frames_dir.empty())
        std::cout << "camera " << c.name << ": " << env.frameCount() << " frames in " << c.frames_dir.string() << '\n';
    }
  }
  if (!args.stats_csv.empty()) {
    try {
      env.timing().writeCsv(args.stats_csv);
      if (summary.timed_steps < summary.steps)
        std::cerr << "ssx: warning: --stats-csv " << args.stats_csv << " holds the newest " << summary.timed_steps
                  << " of " << summary.steps << " steps (the timing ring keeps " << env.timing().capacity()
                  << "; EnvironmentSettings::timing_samples sets it)\n";
    } catch (const std::exception& e) {
      std::cerr << "ssx: error: " << e.what() << '\n';
      status = kExitRunFailure;
    }
  }
  // stopped by SIGINT or SIGTERM: as a shell reports a process those signals ended (130, 143),
  // after everything above was done (the state saved, files closed)
  if (status == 0 && g_signal != 0) return 128 + g_signal;
  return status;
}

int commandValidate(const std::string& file, const std::vector<std::string>& plugin_path, const std::string& physics,
                    bool print, double max_input_mb) {
  ssx::SceneOptions options;
  options.plugin_path = pluginPath(plugin_path);
  options.max_input_bytes = maxInputBytes(max_input_mb);
  // (outputs resolved as `ssx run` resolves them: the same checks, the same messages)
  options.output_directory = outputDirectory(file, "");
  if (!physics.empty()) options.physics_engine = physics;
  try {
    const ssx::Scene scene = ssx::loadScene(file, options);
    if (print) {
      // the scene as the model holds it, every default filled in (nothing else on standard output)
      printWarnings(scene);
      std::cout << ssx::parseScene(file, options).toXml();
      return 0;
    }
    printWarnings(scene);
    std::cout << file << ": ok: " << scene.environment->artifactCount() << " artifacts, " << scene.warnings.size()
              << " warning(s); physics engine " << scene.environment->settings().physics.engine << " (available: "
              << joined(ssx::physicEngineNames()) << "), render engine " << scene.environment->settings().render.engine
              << " (available: " << joined(ssx::renderEngineNames()) << ")\n";
    return 0;
  } catch (const ssx::SceneError& e) {
    printSorted(e);
    return kExitBadInput;
  }
}

int commandImport(const ImportArgs& args) {
  ssx::SceneOptions options;
  for (const std::string& d : args.resource_path) options.resource_path.emplace_back(d);
  options.max_input_bytes = maxInputBytes(args.max_input_mb);
  const fs::path out = args.out;
  std::error_code ec;
  // a new file: never over one the user has (the description itself, say)
  if (!out.empty() && fs::exists(out, ec)) {
    std::cerr << "ssx import: error: " << out.string() << " exists; give --out a new file (nothing was written)\n";
    return kExitBadInput;
  }
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const ssx::ImportedRobot robot =
        ssx::importRobotDescription(args.file, out.empty() ? fs::current_path(ec) : fs::absolute(out, ec).parent_path(), options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (const auto& w : robot.warnings) std::cerr << w.str() << '\n';
    if (out.empty()) {
      std::cout << robot.artifact_xml;
    } else {
      std::ofstream f(out, std::ios::binary);
      f << robot.artifact_xml;
      f.close();
      if (!f) {
        std::cerr << "ssx import: error: could not write " << out.string() << '\n';
        fs::remove(out, ec);
        return kExitRunFailure;
      }
    }
    std::fprintf(stderr, "%s: %zu bodies, %zu joints, %.4g kg; read in %.3f s\n", args.file.c_str(), robot.bodies,
                 robot.joints, robot.mass, seconds);
    return 0;
  } catch (const ssx::SceneError& e) {
    printSorted(e);
    return kExitBadInput;
  }
}

int commandSweep(const SweepArgs& args) {
  namespace sw = ssx::sweep;
  const fs::path out = args.out.empty() ? fs::path(fs::path(args.file).stem().string() + ".csv") : fs::path(args.out);
  const auto plugin_path = pluginPath(args.plugin_path);
  const std::uintmax_t max_input = maxInputBytes(args.max_input_mb);
  if (sw::underMpi()) return sw::runMpi(args.file, plugin_path, out, args.robots, args.check, max_input);
  std::optional<sw::Spec> spec;
  try {
    spec = sw::readSpec(args.file, plugin_path, max_input);
    sw::check(*spec);
  } catch (const ssx::SceneError& e) {
    printSorted(e);
    return kExitBadInput;
  }
  if (args.check) {
    std::cout << args.file << ": ok: " << spec->points.size() << " point(s) x " << spec->seeds
              << " seed(s) = " << spec->runCount() << " runs\n";
    return 0;
  }
  std::optional<sw::Output> output;
  try {
    output.emplace(*spec, out, args.robots);
  } catch (const std::exception& e) {
    std::cerr << "ssx: error: " << e.what() << '\n';
    return kExitBadInput;
  }
  if (output->pending() == 0) {
    std::cout << "ssx sweep: all " << spec->runCount() << " runs are in " << out.string() << "; nothing to do\n";
    return 0;
  }
  if (output->pending() < spec->runCount())
    std::cout << "ssx sweep: resuming: " << spec->runCount() - output->pending() << " of " << spec->runCount()
              << " runs are in " << out.string() << '\n';
  const int jobs = args.jobs > 0 ? args.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const sw::Stats stats = sw::runLocal(*spec, *output, jobs, !args.quiet && isatty(STDERR_FILENO) == 1);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    sw::printStats(stats, *output, wall, jobs, output->writeSummary());
  } catch (const std::exception& e) {
    std::cerr << "ssx: error: " << e.what() << '\n';
    return kExitRunFailure;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const CommandLine c = parseCommandLine(argc, argv, std::cout, std::cerr);
  if (c.exit_status) return *c.exit_status;
  // memory running out anywhere (a scene larger than the estimate foresaw): a message and status 1,
  // not an abort
  try {
    switch (c.command) {
      case CommandLine::Command::Run: return commandRun(c.run, c.realtime_given);
      case CommandLine::Command::Validate:
        return commandValidate(c.validate.scene, c.validate.plugin_path, c.validate.physics, c.validate.print,
                               c.validate.max_input_mb);
      case CommandLine::Command::Sweep: return commandSweep(c.sweep);
      case CommandLine::Command::Import: return commandImport(c.import);
      case CommandLine::Command::Inspect: return ssx::cli::commandInspect(c.inspect);
      case CommandLine::Command::Replay: return ssx::cli::commandReplay(c.replay);
      case CommandLine::Command::Plugins:
        if (!c.plugins.inspect_file.empty()) return ssx::cli::inspectOne(c.plugins.inspect_file, c.plugins.params_of);
        return ssx::cli::commandPlugins(c.plugins.plugin_path, c.plugins.params_of);
    }
  } catch (const std::bad_alloc&) {
    std::cerr << "ssx: error: out of memory (the scene needs more than this machine has: make its swarms smaller)\n";
    return kExitRunFailure;
  }
  return kExitBadInput;
}
