#pragma once
/// @file
/// Step timing: what each step cost, per phase, and how late it was; summaries and CSV.

#include <ssx/export.hpp>
#include <ssx/types.hpp>

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace ssx {

/// Wall-clock cost of one step, in nanoseconds.
struct StepTiming {
  std::int64_t step = 0;
  Nanoseconds physics = 0;   ///< the engine's own step (collision and integration)
  Nanoseconds snapshot = 0;  ///< publishing the new state, checking it for NaN
  Nanoseconds sensors = 0;   ///< parallel sensors phase
  Nanoseconds drivers = 0;   ///< parallel callbacks and drivers phase
  Nanoseconds render = 0;    ///< render phase (0 when not due)
  Nanoseconds total = 0;     ///< the whole step, extensions included
  Nanoseconds lateness = 0;  ///< run loop only: how far past its deadline the step ended (0 if on time)
};

/// Summary of a series of steps.
struct SSX_EXPORT TimingSummary {
  std::int64_t steps = 0;
  double median_ms = 0, p95_ms = 0, p99_ms = 0, max_ms = 0, mean_ms = 0;  ///< step compute time
  double physics_median_ms = 0, sensors_median_ms = 0, drivers_median_ms = 0, render_median_ms = 0;
  std::int64_t overruns = 0;  ///< steps that ended after their deadline (real-time runs)
  double max_lateness_ms = 0;
  double wall_s = 0;           ///< wall-clock time of the run
  double simulated_s = 0;      ///< simulated time covered
  double realtime_factor = 0;  ///< simulated_s / wall_s

  /// A human-readable block of lines.
  std::string str() const;
};

/// Collects StepTiming samples. Not thread-safe; written by the thread that steps.
class SSX_EXPORT TimingRecorder {
 public:
  /// Keeps at most `max_samples` samples (oldest dropped beyond that); summaries cover those.
  explicit TimingRecorder(std::size_t max_samples = 50'000'000);

  void add(const StepTiming& sample);
  void clear();
  const std::vector<StepTiming>& samples() const noexcept { return samples_; }
  /// Summary over the kept samples from index `first` on; `wall` and `simulated` fill the rate
  /// fields; `overruns` counts samples with lateness > 0.
  TimingSummary summary(Nanoseconds wall = 0, Nanoseconds simulated = 0, std::size_t first = 0) const;
  /// The newest sample, for the run loop to fill in lateness; nullptr when empty.
  StepTiming* last() noexcept { return samples_.empty() ? nullptr : &samples_.back(); }
  /// Writes the samples as CSV with a header (times in nanoseconds).
  void writeCsv(std::ostream& out) const;
  /// Same, to a file; throws Error if it cannot be written.
  void writeCsv(const std::string& path) const;

 private:
  std::size_t max_samples_;
  std::vector<StepTiming> samples_;
};

}  // namespace ssx
