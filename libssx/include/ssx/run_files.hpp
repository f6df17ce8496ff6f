#pragma once
/// @file
/// The files a run reads and writes, checked before anything is opened: no output may be a file the
/// run reads or another of its outputs (compared by identity: the same file under another spelling,
/// a hard link or a symbolic link is the same file), and an output must be a regular file or a new
/// one in an existing directory. A FIFO, a device, a directory or a symbolic link as an output is
/// refused: a run replaces its outputs, and would replace those instead of writing through them.
/// The scene loader fills in the scene's inputs and the outputs its plugins declare
/// (SSX_PARAM_OUTPUT); the CLI, Python and programs add theirs (a state to save, timing samples).

#include <ssx/export.hpp>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace ssx {

/// The largest file a run reads as input unless told otherwise (SceneOptions::max_input_bytes,
/// `ssx run|validate|sweep --max-input-mb`): 64 MiB, far beyond any scene, artifact, sweep, saved
/// state or trajectory of a swarm of 100,000 robots.
inline constexpr std::uintmax_t kDefaultMaxInputBytes = std::uintmax_t{64} << 20;

/// Reads a whole input file of the run. It must be a regular file (a FIFO, a device such as
/// /dev/zero, or a directory is refused: they have no end or no content) of at most `max_bytes`.
/// Throws ConfigError at the file (line 0) saying what is wrong and what to do.
SSX_EXPORT std::string readInputFile(const std::filesystem::path& file, std::uintmax_t max_bytes = kDefaultMaxInputBytes);

/// Opens `file` to write a run's output into (binary), creating it when new, under an advisory
/// lock (flock) held until it is closed: a second run writing the same file at the same time is
/// refused with an Error saying so, before anything in the file changes, rather than both writing
/// it and one run's output being lost. Then the file is emptied (unless `append`). A FIFO or a
/// device (an output allowed to be one) is opened as it is, without a lock. The caller closes it
/// (std::fclose releases the lock).
SSX_EXPORT std::FILE* openOutputFile(const std::filesystem::path& file, bool append = false);

/// The files one run reads and writes, checked against each other before anything is opened:
/// no output is an input or another output (however spelled: symlinks and `..` resolved), and
/// no output is a special file unless allowed. The scene loader and the CLI fill one in.
class SSX_EXPORT RunFiles {
 public:
  /// Outputs written as a stream (a logger's file, timing samples) may then be a FIFO or a
  /// character device (a pipe to another program, /dev/null): SceneOptions::allow_special_outputs,
  /// `ssx run --allow-special-outputs`. Outputs a run replaces (a saved state) never may.
  void allowSpecialOutputs(bool allow) { allow_special_ = allow; }
  /// A file the run reads (a scene, an included or artifact file, a state to load).
  void addInput(const std::filesystem::path& file);
  /// Claims `path` as an output of the run (`replaced`: written beside it and renamed over it, as a
  /// saved state is, so never a special file). Returns what is wrong with it ("" when nothing is, and
  /// then it is recorded); `what` names it in the message ("--save-state", "parameter 'file'").
  /// (`makes_directory`: its writer creates the directory it goes in, so that need not exist yet.)
  std::string claimOutput(const std::filesystem::path& path, const std::string& what, bool replaced = false,
                          bool makes_directory = false);
  /// Claims a directory the run writes files into (PNG frames): it may exist or be new, must hold
  /// no input of the run, and must not be claimed twice. Returns what is wrong ("" when nothing is).
  std::string claimOutputDirectory(const std::filesystem::path& dir, const std::string& what);
  /// The inputs added, as given.
  const std::vector<std::filesystem::path>& inputs() const { return inputs_; }
  /// The outputs claimed, as given.
  const std::vector<std::filesystem::path>& outputs() const { return outputs_; }

 private:
  struct Identity {
    bool exists = false;
    std::uintmax_t device = 0, inode = 0;
    std::string path;  // absolute and normal (for a file that does not exist yet)
    bool operator==(const Identity& o) const;
  };
  static Identity identify(const std::filesystem::path& file);
  std::vector<std::filesystem::path> inputs_, outputs_, directories_;
  std::vector<Identity> input_ids_, output_ids_, directory_ids_;
  bool allow_special_ = false;
};

}  // namespace ssx
