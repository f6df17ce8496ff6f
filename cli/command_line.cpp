#include "command_line.hpp"

#include "number_options.hpp"

#include <ssx/ssx.hpp>

#include <CLI/CLI.hpp>

#include <arpa/inet.h>

#include <algorithm>

#include <limits>
#include <ostream>

namespace ssx::cli {

namespace {

// a file or directory name: never empty (an empty name would be taken as "not given" and the
// output silently not written)
CLI::Validator path() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        return text.empty() ? std::string("an empty name: give a file or directory name") : std::string();
      },
      "PATH");
}

// an address to listen on: one IPv4 address or localhost, nothing else (civetweb takes lists and
// "+" in it and would listen wider than asked)
CLI::Validator listenAddress() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        in_addr address{};
        if (text == "localhost" || inet_pton(AF_INET, text.c_str(), &address) == 1) return {};
        return "must be one IPv4 address (127.0.0.1; 0.0.0.0 for every interface) or localhost, got '" + text + "'";
      },
      "ADDR");
}

void addMaxInputOption(CLI::App* command, double& mb) {
  command->add_option("--max-input-mb", mb, "largest input file read (scene, include, artifact, sweep, state), MiB")
      ->check(realNumber(1.0 / 1024, kMostMaxInputMb))
      ->default_val(kDefaultMaxInputMb);
}

// --view [PORT] and --view-bind ADDR on `command`; --view alone: port 8765 (viewPort)
CLI::Option* addViewOptions(CLI::App* command, int& port, std::string& bind, const char* what) {
  auto* view = command->add_option("--view", port, std::string(what) + " (default 8765; 0: a free port)")
                   ->expected(0, 1)
                   ->check(CLI::Range(0, 65535));
  command->add_option("--view-bind", bind,
                      "address the page is served on (default 127.0.0.1; another prints a token the page's URL needs)")
      ->check(listenAddress())
      ->needs(view);
  return view;
}

void viewPort(const CLI::Option* view, int& port) {
  if (view->count() > 0 && (view->results().empty() || view->results().front().empty())) port = 8765;
}

}  // namespace

CommandLine parseCommandLine(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CommandLine c;
  CLI::App app{"ssx: real-time simulation of robot swarms"};
  app.set_version_flag("--version", std::string("ssx ") + SSX_VERSION_STRING);
  app.require_subcommand(1);

  CLI::App* run_cmd = app.add_subcommand("run", "run a scene");
  run_cmd->add_option("scene", c.run.scene, "scene file")->required()->check(CLI::ExistingFile);
  auto* duration =
      run_cmd->add_option("--duration", c.run.duration, "simulated seconds to run")
          ->check(realNumber(0.0, ssx::kMaxDurationSeconds, true));
  run_cmd->add_option("--steps", c.run.steps, "steps to run")->check(wholeNumber(0, std::numeric_limits<std::int64_t>::max()))->excludes(duration);
  auto* realtime =
      run_cmd->add_option("--realtime", c.run.realtime, "pace against the wall clock, optionally FACTOR times faster")
          ->expected(0, 1)
          ->check(realNumber(ssx::kMinRealtimeFactor, ssx::kMaxRealtimeFactor));
  auto* fast = run_cmd->add_flag("--fast", c.run.fast, "run as fast as possible")->excludes(realtime);
  auto* view = addViewOptions(run_cmd, c.run.view, c.run.view_bind,
                              "serve a live 3D view of the run to web browsers at http://127.0.0.1:PORT/");
  run_cmd->add_flag("--view-wait", c.run.view_wait, "hold the run after its first step until a page connects to --view")
      ->needs(view);
  auto* foxglove = run_cmd->add_option("--foxglove", c.run.foxglove,
                                       "serve the run live to Foxglove at ws://127.0.0.1:PORT (default 8765, "
                                       "Foxglove's own; 0: a free port)")
                       ->expected(0, 1)
                       ->check(CLI::Range(0, 65535));
  run_cmd->add_option("--foxglove-bind", c.run.foxglove_bind,
                      "address the Foxglove server listens on (default 127.0.0.1; another prints a token the URL needs)")
      ->check(listenAddress())
      ->needs(foxglove);
  run_cmd
      ->add_option("--rt-priority", c.run.rt_priority,
                   "step at this SCHED_FIFO priority (1-99; needs root or CAP_SYS_NICE): steps are not woken late "
                   "while other processes run")
      ->check(wholeNumber(ssx::kMinRealtimePriority, ssx::kMaxRealtimePriority))
      ->excludes(fast);
  run_cmd->add_option("--threads", c.run.threads, "worker threads (0: one per core)")->check(wholeNumber(0, 1024));
  run_cmd->add_option("--seed", c.run.seed, "scene seed")->check(seedNumber());
  run_cmd->add_option("--plugin-path", c.run.plugin_path, "plugin directory (repeatable)")->check(path());
  run_cmd->add_option("--stats-csv", c.run.stats_csv, "write per-step timing samples to FILE")->check(path());
  run_cmd->add_flag("--quiet", c.run.quiet, "no progress, no summary");
  run_cmd->add_option("--render", c.run.render, "render engine (overrides the scene's): null or osmesa");
  run_cmd->add_option("--physics", c.run.physics, "physics engine (overrides the scene's): ode or bullet")
      ->check(CLI::IsMember(ssx::physicEngineNames()));
  run_cmd->add_option("--switch-physics", c.run.switch_physics,
                      "continue the run on another physics engine from a time on, SECONDS:ENGINE (repeatable: "
                      "1.5:bullet 3:ode); bodies, joints and the robots' state carry over")
      ->check(switchSpec());
  run_cmd->add_option("--snapshot", c.run.snapshot, "write the first camera's last frame as PNG to FILE")->check(path());
  run_cmd->add_option("--video", c.run.video, "write the first camera's frames as MP4 to FILE (needs ffmpeg)")->check(path());
  run_cmd->add_option("--frames", c.run.frames, "write the first camera's frames as PNG files into DIR")->check(path());
  run_cmd->add_option("--frames-from", c.run.frames_from,
                      "start the cameras' frames (video, PNG frames, snapshot) at this simulated second")
      ->check(realNumber(0.0, ssx::kMaxDurationSeconds));
  auto* frames_until = run_cmd->add_option("--frames-until", c.run.frames_until,
                                           "end the cameras' frames after this simulated second (outputs finished then)")
                           ->check(realNumber(0.0, ssx::kMaxDurationSeconds));
  run_cmd->add_option("--save-state", c.run.save_state, "write the world's state to FILE at the end (ssx run --load-state)")->check(path());
  auto* record = run_cmd->add_option("--record", c.run.record,
                      "record the run into FILE (MCAP: the scene, every body's pose, saved states; ssx inspect, "
                      "ssx replay, ssx.Recording)")->check(path());
  run_cmd->add_option("--record-rate", c.run.record_rate, "pose samples per simulated second in --record (0: every step)")
      ->check(realNumber(0.0, 1e6))
      ->needs(record);
  run_cmd->add_option("--record-channels", c.run.record_channels,
                      "channels recorded besides the poses, comma-separated: foxglove (/tf and /scene for Foxglove and "
                      "Lichtblick), timing (/ssx/timing, each step's cost), sensors (/ssx/sensors: IMU, pose, range), "
                      "commands (/ssx/commands), contacts (/ssx/contacts: pairs, points, impulses), none (default: "
                      "foxglove for swarms up to 1,000 bodies)")
      ->delimiter(',')
      ->check(CLI::IsMember({"foxglove", "timing", "sensors", "commands", "contacts", "none"}))
      ->needs(record);
  run_cmd->add_option("--record-states", c.run.record_states,
                      "simulated seconds between saved states in --record (0: only the first)")
      ->check(realNumber(0.0, ssx::kMaxDurationSeconds))
      ->needs(record);
  run_cmd->add_flag("--allow-special-outputs", c.run.allow_special_outputs,
                    "let outputs written as streams (a logger's file, --stats-csv) be FIFOs or devices");
  run_cmd->add_option("--load-state", c.run.load_state,
                      "continue from a state saved from this scene (--steps and --duration count from there)")
      ->check(CLI::ExistingFile);
  run_cmd->add_option("--out", c.run.out,
                      "directory for the scene's own outputs (its loggers' files, its cameras' pictures) given as "
                      "relative paths (default: ssx-out/SCENE/; --out . for the working directory)")->check(path());
  addMaxInputOption(run_cmd, c.run.max_input_mb);

  CLI::App* validate_cmd = app.add_subcommand("validate", "check a scene and its plugins; run nothing");
  validate_cmd->add_option("scene", c.validate.scene, "scene file")->required()->check(CLI::ExistingFile);
  validate_cmd->add_option("--plugin-path", c.validate.plugin_path, "plugin directory (repeatable)")->check(path());
  validate_cmd->add_flag("--print", c.validate.print,
                         "print the scene as ssx reads it, every default filled in (scene XML, on standard output)");
  validate_cmd->add_option("--physics", c.validate.physics, "check the scene for this physics engine: ode or bullet")
      ->check(CLI::IsMember(ssx::physicEngineNames()));
  addMaxInputOption(validate_cmd, c.validate.max_input_mb);

  CLI::App* import_cmd =
      app.add_subcommand("import", "read a robot description (URDF) and print it as an ssx artifact file (docs/robots.md)");
  import_cmd->add_option("file", c.import.file, "robot description (.urdf)")->required()->check(CLI::ExistingFile);
  import_cmd->add_option("--out", c.import.out, "write the artifact file here (a new file) instead of standard output")
      ->check(path());
  import_cmd->add_option("--resource-path", c.import.resource_path,
                         "where package://NAME/ and model://NAME/ are looked for, before SSX_RESOURCE_PATH (repeatable)")
      ->check(path());
  addMaxInputOption(import_cmd, c.import.max_input_mb);

  CLI::App* plugins_cmd = app.add_subcommand("plugins", "list plugin libraries, their classes, and ABI checks");
  plugins_cmd->add_option("--plugin-path", c.plugins.plugin_path, "plugin directory (repeatable)")->check(path());
  plugins_cmd->add_option("--params", c.plugins.params_of, "print the declared parameters of plugin class NAME, or the settings of physics engine NAME (a Markdown table)");
  plugins_cmd->add_option("--inspect", c.plugins.inspect_file, "(internal) report one library from a child process")
      ->group("");

  CLI::App* sweep_cmd =
      app.add_subcommand("sweep", "run a scene many times over varied attributes and seeds (docs/sweep-format.md)");
  sweep_cmd->add_option("sweep", c.sweep.file, "sweep file")->required()->check(CLI::ExistingFile);
  sweep_cmd->add_option("--out", c.sweep.out, "results CSV (default: SWEEP's name .csv); an existing one is resumed")->check(path());
  sweep_cmd->add_option("--robots", c.sweep.robots, "also write per-robot metrics to this CSV")->check(path());
  sweep_cmd->add_option("--jobs", c.sweep.jobs, "worker processes (default: one per core; under mpirun: the ranks)")
      ->check(wholeNumber(1, 4096));
  sweep_cmd->add_option("--plugin-path", c.sweep.plugin_path, "plugin directory (repeatable)")->check(path());
  sweep_cmd->add_flag("--check", c.sweep.check, "check the sweep and every point's scene; run nothing");
  sweep_cmd->add_flag("--quiet", c.sweep.quiet, "no progress");
  addMaxInputOption(sweep_cmd, c.sweep.max_input_mb);

  CLI::App* inspect_cmd = app.add_subcommand("inspect", "say what a recording (ssx run --record) holds");
  inspect_cmd->add_option("file", c.inspect.file, "recording (MCAP)")->required()->check(CLI::ExistingFile);
  inspect_cmd->add_option("--complete", c.inspect.complete,
                          "write a complete copy to FILE (of a recording cut short: summary and footer added)")->check(path());
  inspect_cmd->add_flag("--json", c.inspect.json, "print as JSON");

  CLI::App* replay_cmd =
      app.add_subcommand("replay", "draw a recording's poses, or re-simulate it from one of its saved states");
  replay_cmd->add_option("file", c.replay.file, "recording (MCAP)")->required()->check(CLI::ExistingFile);
  auto* from = replay_cmd->add_option("--from", c.replay.from, "first simulated second drawn")->check(realNumber(0.0, ssx::kMaxDurationSeconds));
  auto* to = replay_cmd->add_option("--to", c.replay.to, "last simulated second drawn")->check(realNumber(0.0, ssx::kMaxDurationSeconds));
  replay_cmd->add_option("--snapshot", c.replay.snapshot, "write the last frame drawn as PNG to FILE")->check(path());
  replay_cmd->add_option("--video", c.replay.video, "write the frames as MP4 to FILE (needs ffmpeg)")->check(path());
  replay_cmd->add_option("--frames", c.replay.frames, "write the frames as PNG files into DIR")->check(path());
  replay_cmd->add_option("--follow", c.replay.follow, "a camera that follows this robot")->check(path());
  replay_cmd->add_option("--speed", c.replay.speed,
                         "recorded seconds per second of the video or frames (0.25: slow motion; 4: four times as "
                         "fast), at the recording's sample rate")
      ->check(realNumber(1e-3, 1e3));
  replay_cmd->add_option("--trails", c.replay.trails, "draw the last S recorded seconds of each robot's path behind it")
      ->check(realNumber(0.0, ssx::kMaxDurationSeconds));
  replay_cmd->add_option("--plugin-path", c.replay.plugin_path, "plugin directory (repeatable)")->check(path());
  replay_cmd
      ->add_option("--resimulate-from", c.replay.resimulate_from,
                   "restore the saved state at or before this simulated second and step the recorded scene again, "
                   "comparing every recorded pose")
      ->check(realNumber(0.0, ssx::kMaxDurationSeconds));
  replay_cmd->add_option("--duration", c.replay.duration, "simulated seconds to re-simulate (default: to the end)")
      ->check(realNumber(0.0, ssx::kMaxDurationSeconds, true));
  replay_cmd->add_option("--set", c.replay.set,
                         "PATH=VALUE: an attribute of the recorded scene set for the re-simulation, as a sweep sets it "
                         "(repeatable)");
  replay_cmd->add_option("--record", c.replay.record, "record the re-simulation into FILE")->check(path());
  auto* replay_view = addViewOptions(replay_cmd, c.replay.view, c.replay.view_bind,
                                     "play the recording in web browsers at http://127.0.0.1:PORT/ until Ctrl-C, with a "
                                     "time slider");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e, out, err);
    c.exit_status = code == 0 ? 0 : kExitBadInput;
    return c;
  }
  if (*run_cmd) {
    c.command = CommandLine::Command::Run;
    // --realtime alone means factor 1
    c.realtime_given = realtime->count() > 0;
    viewPort(view, c.run.view);
    viewPort(foxglove, c.run.foxglove);
    if (c.run.view > 0 && c.run.view == c.run.foxglove) {
      err << "ssx run: --view and --foxglove both on port " << c.run.view << ": give one of them another port "
          << "(--foxglove 8766)\n";
      c.exit_status = kExitBadInput;
    }
    c.run.duration_given = duration->count() > 0;
    if (c.realtime_given && (realtime->results().empty() || realtime->results().front().empty())) c.run.realtime = 1.0;
    if (frames_until->count() > 0 && c.run.frames_until < c.run.frames_from) {
      err << "ssx run: --frames-from " << c.run.frames_from << " --frames-until " << c.run.frames_until
          << ": an empty window (--frames-until comes before --frames-from)\n";
      c.exit_status = kExitBadInput;
    }
    const auto& channels = c.run.record_channels;
    if (channels.size() > 1 && std::find(channels.begin(), channels.end(), "none") != channels.end()) {
      err << "ssx run: --record-channels: 'none' cannot go with other channels\n";
      c.exit_status = kExitBadInput;
    }
  } else if (*validate_cmd) {
    c.command = CommandLine::Command::Validate;
  } else if (*import_cmd) {
    c.command = CommandLine::Command::Import;
  } else if (*sweep_cmd) {
    c.command = CommandLine::Command::Sweep;
  } else if (*inspect_cmd) {
    c.command = CommandLine::Command::Inspect;
  } else if (*replay_cmd) {
    c.command = CommandLine::Command::Replay;
    viewPort(replay_view, c.replay.view);
    const ReplayArgs& r = c.replay;
    if (r.view >= 0 && (r.resimulate_from >= 0 || !r.snapshot.empty() || !r.video.empty() || !r.frames.empty())) {
      err << "ssx replay: --view plays the recording on a page: it does not go with --resimulate-from, --snapshot, "
             "--video or --frames\n";
      c.exit_status = kExitBadInput;
    }
    if (from->count() > 0 && to->count() > 0 && r.to < r.from) {
      err << "ssx replay: --from " << r.from << " --to " << r.to << ": an empty window (--to comes before --from)\n";
      c.exit_status = kExitBadInput;
    }
    if (c.replay.resimulate_from < 0 && (!c.replay.set.empty() || !c.replay.record.empty() || c.replay.duration > 0)) {
      err << "ssx replay: --set, --record and --duration need --resimulate-from\n";
      c.exit_status = kExitBadInput;
    }
  } else if (*plugins_cmd) {
    c.command = CommandLine::Command::Plugins;
  } else {
    c.exit_status = kExitBadInput;
  }
  return c;
}

}  // namespace ssx::cli
