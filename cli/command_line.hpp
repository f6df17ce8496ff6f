#pragma once
// The ssx command's command line: its subcommands and options, parsed and checked (numbers by
// cli/number_options.hpp) without running anything. main.cpp runs what it asks for; the fuzz
// target tests/fuzz/command_line_fuzz.cpp feeds it arbitrary arguments.
#include "common.hpp"

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace ssx::cli {

struct RunArgs {
  std::string scene;
  double duration = 0;
  std::int64_t steps = -1;
  double realtime = 1.0;
  int view = -1;                       // --view: the viewer's port (8765 when given bare); -1: no viewer
  std::string view_bind = "127.0.0.1";  // --view-bind: the viewer's address (another needs the printed token)
  bool view_wait = false;               // --view-wait: hold the run after its first step until a page connects
  int foxglove = -1;                        // --foxglove: the Foxglove server's port (8765 bare); -1: none
  std::string foxglove_bind = "127.0.0.1";  // --foxglove-bind: its address (another needs the printed token)
  bool fast = false;
  int threads = -1;
  std::optional<std::uint64_t> seed;
  std::vector<std::string> plugin_path;
  std::string stats_csv;
  bool quiet = false;
  double max_input_mb = kDefaultMaxInputMb;
  std::string render, physics, snapshot, video, frames;
  std::string save_state, load_state;
  std::string record;          // an MCAP recording of the run (empty: none)
  double record_rate = 25;     // pose samples per simulated second (0: every step)
  double record_states = 10;   // simulated seconds between saved states in the recording
  // channels besides the poses: foxglove, timing, sensors, commands, none (given: exactly these; not given:
  // foxglove for swarms up to RecordOptions::kFoxgloveAutoBodies bodies)
  std::vector<std::string> record_channels;
  std::string out;  // the scene's own outputs (empty: ssx-out/<scene>/)
  bool allow_special_outputs = false;
  bool duration_given = false;
  int rt_priority = 0;
  std::vector<std::string> switch_physics;  // --switch-physics SECONDS:ENGINE, each
  double frames_from = 0;    // --frames-from: the scene cameras' frames start at this simulated second
  double frames_until = -1;  // --frames-until: ... and end after this one (< 0: at the end)
};

struct ValidateArgs {
  std::string scene;
  std::vector<std::string> plugin_path;
  std::string physics;
  bool print = false;
  double max_input_mb = kDefaultMaxInputMb;
};

struct SweepArgs {
  std::string file, out, robots;
  std::vector<std::string> plugin_path;
  int jobs = 0;
  bool check = false, quiet = false;
  double max_input_mb = kDefaultMaxInputMb;
};

struct PluginsArgs {
  std::vector<std::string> plugin_path;
  std::string params_of;
  std::string inspect_file;  // (internal) one library, reported from a child process
};

struct InspectArgs {
  std::string file;
  std::string complete;  // write a complete copy here
  bool json = false;
};

struct ReplayArgs {
  std::string file;
  double from = 0, to = -1;  // seconds; to < 0: the end
  double speed = 1;          // recorded seconds per second of the video or frames
  double trails = 0;         // seconds of each robot's path drawn behind it (0: none)
  std::string snapshot, video, frames, follow;
  std::vector<std::string> plugin_path;
  double resimulate_from = -1;  // seconds; < 0: draw the recorded poses only
  double duration = -1;         // of a re-simulation; < 0: to the recording's end
  std::vector<std::string> set;  // PATH=VALUE overrides of the recorded scene, for a re-simulation
  std::string record;           // record the re-simulation
  int view = -1;                // play it on a page at this port (0: a free one); < 0: no
  std::string view_bind = "127.0.0.1";
};

struct ImportArgs {
  std::string file;  // URDF
  std::string out;   // the artifact file to write (empty: standard output)
  std::vector<std::string> resource_path;
  double max_input_mb = kDefaultMaxInputMb;
};

struct CommandLine {
  enum class Command { Run, Validate, Sweep, Plugins, Inspect, Replay, Import };
  /// Set when parsing ended the command: --help or --version (0), bad arguments (kExitBadInput);
  /// what CLI11 had to say went to the streams given.
  std::optional<int> exit_status;
  Command command = Command::Run;
  RunArgs run;
  bool realtime_given = false;  // --realtime, with or without a factor
  ValidateArgs validate;
  SweepArgs sweep;
  PluginsArgs plugins;
  InspectArgs inspect;
  ReplayArgs replay;
  ImportArgs import;
};

/// Parses argv (argv[0] the program). Never throws for bad arguments.
CommandLine parseCommandLine(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace ssx::cli
