#pragma once
// `ssx sweep`: many runs of one scene over varied attributes and seeds, their metrics in a CSV.
//
//   sweep.cpp           the sweep file, its checks before any run, one run and its metrics
//   sweep_output.cpp    the results file (rows as runs finish, resume) and the per-point summary
//   sweep_schedule.cpp  who runs what: worker processes on this machine, or MPI ranks
//
// The format is described in docs/sweep-format.md.
#include <ssx/ssx.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace ssx::sweep {

namespace fs = std::filesystem;

struct Parameter {
  std::string name;    // its column
  std::string target;  // AttributeOverride::target
  std::vector<std::string> values;  // list and grid
  double min = 0, max = 0;          // random
  bool integer = false, log = false;
  SourceLocation where;
};

struct MetricSpec {
  std::string kind;    // tracking_error, min_distance, contacts, state_hash, settle_time, or a plugin metric
  std::string of;      // settle_time: the per-sample value it watches
  double below = 0;    // settle_time: the threshold
  std::string column;  // settle_time's column; others derive theirs
  SourceLocation where;
};

struct Spec {
  fs::path file;
  SourceLocation where;  // the <sweep> element
  fs::path scene;
  std::uint64_t seed = 0;
  std::int64_t seeds = 1;  // runs per point
  std::optional<double> duration;
  int threads = 1;  // per run
  double sample_hz = 50;
  bool extensions = false;
  std::vector<fs::path> plugin_path;
  std::vector<Parameter> parameters;
  std::vector<std::vector<std::string>> points;  // one value per parameter
  std::vector<MetricSpec> metrics;
  std::string fingerprint;  // of the sweep file and the scene file's text
  std::uintmax_t max_input_bytes = kDefaultMaxInputBytes;  // of every file read (--max-input-mb)

  std::int64_t runCount() const { return static_cast<std::int64_t>(points.size()) * seeds; }
  std::size_t pointOf(std::int64_t run) const { return static_cast<std::size_t>(run / seeds); }
  /// Each run's scene seed: from the sweep seed and the run index only.
  std::uint64_t seedOf(std::int64_t run) const { return deriveSeed(seed, static_cast<std::uint64_t>(run), 0x5357); }
  /// The columns every row has, in order.
  std::vector<std::string> columns() const;
  std::vector<std::string> metricColumns() const;
};

/// Reads a sweep file; throws SceneError with every problem (file:line).
Spec readSpec(const fs::path& file, const std::vector<fs::path>& plugin_path,
              std::uintmax_t max_input_bytes = kDefaultMaxInputBytes);

/// Loads the scene at every point (each value checked by its plugin's declarations) and starts
/// the first point once to learn the metrics its plugins publish. Throws SceneError.
void check(const Spec& spec);

/// The result of one run.
struct Result {
  std::int64_t run = -1;
  std::string row;                  // the CSV row, no newline
  std::vector<std::string> robots;  // per-robot CSV rows
  double load_ms = 0, start_ms = 0, run_ms = 0;
  bool ok = false;
  std::string text() const;  // for the way between processes
  static Result parse(const std::string& text);
};

/// Runs one run (as fast as it goes) and collects its metrics. Never throws: a failure is a row.
Result execute(const Spec& spec, std::int64_t run);
/// The row of a run whose process died.
Result crashed(const Spec& spec, std::int64_t run, const std::string& why);

/// The results file: rows appended as runs finish, each flushed; a second call with the same file
/// skips the runs it holds. Throws std::runtime_error when it cannot write (disk full, ...).
class Output {
 public:
  Output(const Spec& spec, fs::path file, fs::path robots_file);
  const std::vector<bool>& done() const noexcept { return done_; }
  std::int64_t pending() const noexcept { return pending_; }
  void write(const Result& r);
  /// Writes <file stem>.summary.csv (mean, std, min, max of each metric per point); returns its path.
  fs::path writeSummary() const;
  double writeMedianMs() const;

 private:
  const Spec& spec_;
  fs::path file_, robots_file_;
  std::FILE* out_ = nullptr;
  std::FILE* robots_ = nullptr;
  std::vector<bool> done_;
  std::int64_t pending_ = 0;
  std::vector<std::vector<std::string>> rows_;  // every row of the file, parsed
  std::vector<double> write_ms_;

 public:
  ~Output();
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;
};

struct Stats {
  std::int64_t runs = 0, failed = 0;
  std::vector<double> load_ms, start_ms, run_ms;
};

/// Runs every pending run on `jobs` worker processes; rows go to `out` as runs finish.
Stats runLocal(const Spec& spec, Output& out, int jobs, bool progress);

/// Whether this process was started by mpirun (and ssx was built with MPI).
bool underMpi();
/// The sweep under MPI: rank 0 checks, hands out runs as ranks free up and writes; the others
/// run. Returns the exit status.
int runMpi(const fs::path& file, const std::vector<fs::path>& plugin_path, const fs::path& out_file,
           const fs::path& robots_file, bool check_only, std::uintmax_t max_input_bytes);

/// Prints the sweep's rate and its cost per run (load, start, run, write).
void printStats(const Stats& stats, const Output& out, double wall_s, int processes, const fs::path& summary);

/// CSV helpers.
std::string csvField(const std::string& s);
std::vector<std::string> csvSplit(const std::string& line);
std::string number(double v);

}  // namespace ssx::sweep
