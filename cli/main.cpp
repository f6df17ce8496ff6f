// ssx: the command-line client. run, validate, sweep; plugins in plugins_command.cpp.
//
// Exit status: 0 success, 2 bad input (scene, arguments, plugins), 1 failure while running.
#include "common.hpp"
#include "number_options.hpp"
#include "plugins_command.hpp"
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

std::string formatFactor(double f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", f);
  return buf;
}

struct RunArgs {
  std::string scene;
  double duration = 0;
  std::int64_t steps = -1;
  double realtime = 1.0;
  bool fast = false;
  int threads = -1;
  std::optional<std::uint64_t> seed;
  std::vector<std::string> plugin_path;
  std::string stats_csv;
  bool quiet = false;
  double max_input_mb = kDefaultMaxInputMb;
  std::string render, physics, snapshot, video, frames;
  std::string save_state, load_state;
  bool allow_special_outputs = false;
  bool duration_given = false;
  int rt_priority = 0;
};

// "ode, bullet"

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

void addMaxInputOption(CLI::App* command, double& mb) {
  command->add_option("--max-input-mb", mb, "largest input file read (scene, include, artifact, sweep, state), MiB")
      ->check(realNumber(1.0 / 1024, kMostMaxInputMb))
      ->default_val(kDefaultMaxInputMb);
}

// written beside the target and renamed over it: a failed write never leaves a short file
void writeFileAtomically(const std::string& path, const std::vector<std::byte>& bytes) {
  const std::string partial = path + ".partial";
  std::FILE* f = std::fopen(partial.c_str(), "wb");
  if (f == nullptr) throw std::runtime_error("cannot write '" + partial + "': " + std::strerror(errno));
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
  // settings of this process for drawing with Mesa's llvmpipe (the library leaves the process
  // alone; a program that embeds it chooses these itself, see the README):
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
    std::cerr << e.what() << '\n';
    return kExitBadInput;
  }
  printWarnings(scene);
  ssx::Environment& env = *scene.environment;
  // this command's own files, with the scene's: nothing is written over what the run reads or
  // writes already, before anything starts
  {
    if (!args.load_state.empty()) scene.files.addInput(args.load_state);
    std::string problem;
    if (!args.save_state.empty()) problem = scene.files.claimOutput(args.save_state, "--save-state", true);
    if (problem.empty() && !args.stats_csv.empty()) problem = scene.files.claimOutput(args.stats_csv, "--stats-csv");
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
  run.on_step = [&progress](const ssx::Environment& e) { progress.update(e); };

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
  int status = 0;
  ssx::TimingSummary summary;
  try {
    env.start();
    if (!loaded.empty()) env.restoreState(loaded);
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
  const std::vector<ssx::CameraSpec> cameras = env.cameras();
  // stop cleanly: plugins destroyed, engines stopped, extensions shut down (files closed)
  try {
    env.stop();
  } catch (const std::exception& e) {
    std::cerr << "ssx: error while stopping: " << e.what() << '\n';
    status = kExitRunFailure;
  }
  if (status == 0) {
    if (!args.quiet) std::cout << summary.str() << '\n';
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
    std::cerr << e.what() << '\n';
    return kExitBadInput;
  }
}

struct SweepArgs {
  std::string file, out, robots;
  std::vector<std::string> plugin_path;
  int jobs = 0;
  bool check = false, quiet = false;
  double max_input_mb = kDefaultMaxInputMb;
};

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
    std::cerr << e.what() << '\n';
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
  CLI::App app{"ssx: real-time simulation of robot swarms"};
  app.set_version_flag("--version", std::string("ssx ") + SSX_VERSION_STRING);
  app.require_subcommand(1);

  RunArgs run;
  CLI::App* run_cmd = app.add_subcommand("run", "run a scene");
  run_cmd->add_option("scene", run.scene, "scene file")->required()->check(CLI::ExistingFile);
  auto* duration =
      run_cmd->add_option("--duration", run.duration, "simulated seconds to run")
          ->check(realNumber(0.0, ssx::kMaxDurationSeconds, true));
  run_cmd->add_option("--steps", run.steps, "steps to run")->check(wholeNumber(0, std::numeric_limits<std::int64_t>::max()))->excludes(duration);
  auto* realtime =
      run_cmd->add_option("--realtime", run.realtime, "pace against the wall clock, optionally FACTOR times faster")
          ->expected(0, 1)
          ->check(realNumber(ssx::kMinRealtimeFactor, ssx::kMaxRealtimeFactor));
  auto* fast = run_cmd->add_flag("--fast", run.fast, "run as fast as possible")->excludes(realtime);
  run_cmd
      ->add_option("--rt-priority", run.rt_priority,
                   "step at this SCHED_FIFO priority (1-99; needs root or CAP_SYS_NICE): steps are not woken late "
                   "while other processes run")
      ->check(wholeNumber(ssx::kMinRealtimePriority, ssx::kMaxRealtimePriority))
      ->excludes(fast);
  run_cmd->add_option("--threads", run.threads, "worker threads (0: one per core)")->check(wholeNumber(0, 1024));
  run_cmd->add_option("--seed", run.seed, "scene seed")->check(seedNumber());
  run_cmd->add_option("--plugin-path", run.plugin_path, "plugin directory (repeatable)");
  run_cmd->add_option("--stats-csv", run.stats_csv, "write per-step timing samples to FILE");
  run_cmd->add_flag("--quiet", run.quiet, "no progress, no summary");
  run_cmd->add_option("--render", run.render, "render engine (overrides the scene's): null or osmesa");
  run_cmd->add_option("--physics", run.physics, "physics engine (overrides the scene's): ode or bullet")
      ->check(CLI::IsMember(ssx::physicEngineNames()));
  run_cmd->add_option("--snapshot", run.snapshot, "write the first camera's last frame as PNG to FILE");
  run_cmd->add_option("--video", run.video, "write the first camera's frames as MP4 to FILE (needs ffmpeg)");
  run_cmd->add_option("--frames", run.frames, "write the first camera's frames as PNG files into DIR");
  run_cmd->add_option("--save-state", run.save_state, "write the world's state to FILE at the end (ssx run --load-state)");
  run_cmd->add_flag("--allow-special-outputs", run.allow_special_outputs,
                    "let outputs written as streams (a logger's file, --stats-csv) be FIFOs or devices");
  run_cmd->add_option("--load-state", run.load_state,
                      "continue from a state saved from this scene (--steps and --duration count from there)")
      ->check(CLI::ExistingFile);
  addMaxInputOption(run_cmd, run.max_input_mb);

  std::string validate_file;
  std::vector<std::string> validate_path;
  CLI::App* validate_cmd = app.add_subcommand("validate", "check a scene and its plugins; run nothing");
  validate_cmd->add_option("scene", validate_file, "scene file")->required()->check(CLI::ExistingFile);
  validate_cmd->add_option("--plugin-path", validate_path, "plugin directory (repeatable)");
  std::string validate_physics;
  bool validate_print = false;
  validate_cmd->add_flag("--print", validate_print,
                         "print the scene as ssx reads it, every default filled in (scene XML, on standard output)");
  validate_cmd->add_option("--physics", validate_physics, "check the scene for this physics engine: ode or bullet")
      ->check(CLI::IsMember(ssx::physicEngineNames()));
  double validate_max_input_mb = kDefaultMaxInputMb;
  addMaxInputOption(validate_cmd, validate_max_input_mb);

  std::vector<std::string> plugins_path;
  CLI::App* plugins_cmd = app.add_subcommand("plugins", "list plugin libraries, their classes, and ABI checks");
  plugins_cmd->add_option("--plugin-path", plugins_path, "plugin directory (repeatable)");
  std::string params_of;
  plugins_cmd->add_option("--params", params_of, "print the declared parameters of class NAME (a Markdown table)");
  std::string inspect_file;
  plugins_cmd->add_option("--inspect", inspect_file, "(internal) report one library from a child process")
      ->group("");

  SweepArgs sweep;
  CLI::App* sweep_cmd =
      app.add_subcommand("sweep", "run a scene many times over varied attributes and seeds (docs/sweep-format.md)");
  sweep_cmd->add_option("sweep", sweep.file, "sweep file")->required()->check(CLI::ExistingFile);
  sweep_cmd->add_option("--out", sweep.out, "results CSV (default: SWEEP's name .csv); an existing one is resumed");
  sweep_cmd->add_option("--robots", sweep.robots, "also write per-robot metrics to this CSV");
  sweep_cmd->add_option("--jobs", sweep.jobs, "worker processes (default: one per core; under mpirun: the ranks)")
      ->check(wholeNumber(1, 4096));
  sweep_cmd->add_option("--plugin-path", sweep.plugin_path, "plugin directory (repeatable)");
  sweep_cmd->add_flag("--check", sweep.check, "check the sweep and every point's scene; run nothing");
  sweep_cmd->add_flag("--quiet", sweep.quiet, "no progress");
  addMaxInputOption(sweep_cmd, sweep.max_input_mb);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }
  auto dispatch = [&]() -> int {
    if (*run_cmd) {
      // --realtime alone means factor 1
      const bool realtime_given = realtime->count() > 0;
      run.duration_given = duration->count() > 0;
      if (realtime_given && (realtime->results().empty() || realtime->results().front().empty())) run.realtime = 1.0;
      return commandRun(run, realtime_given);
    }
    if (*validate_cmd) return commandValidate(validate_file, validate_path, validate_physics, validate_print, validate_max_input_mb);
    if (*sweep_cmd) return commandSweep(sweep);
    if (*plugins_cmd && !inspect_file.empty()) return ssx::cli::inspectOne(inspect_file, params_of);
    if (*plugins_cmd) return ssx::cli::commandPlugins(plugins_path, params_of);
    return kExitBadInput;
  };
  // memory running out anywhere (a scene larger than the estimate foresaw): a message and status 1,
  // not an abort
  try {
    return dispatch();
  } catch (const std::bad_alloc&) {
    std::cerr << "ssx: error: out of memory (the scene needs more than this machine has: make its swarms smaller)\n";
    return kExitRunFailure;
  }
}
