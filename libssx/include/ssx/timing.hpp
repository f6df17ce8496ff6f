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
  std::int64_t step = 0;     ///< index of the step
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
  std::int64_t steps = 0;        ///< every step summarised (of a run: every step it made)
  std::int64_t timed_steps = 0;  ///< the newest of them whose times the ring kept: what the times below cover
  double median_ms = 0;  ///< step compute time: median
  double p95_ms = 0;     ///< step compute time: 95th percentile
  double p99_ms = 0;     ///< step compute time: 99th percentile
  double max_ms = 0;     ///< step compute time: the longest
  double mean_ms = 0;    ///< step compute time: mean
  double physics_median_ms = 0;  ///< median of the physics phase
  double sensors_median_ms = 0;  ///< median of the sensors phase
  double drivers_median_ms = 0;  ///< median of the drivers phase
  double render_median_ms = 0;   ///< median of the render phase
  std::int64_t overruns = 0;  ///< steps that ended after their deadline (real-time runs)
  /// Of the overruns, as Environment::run tells them apart (a summary made by TimingRecorder
  /// alone leaves both 0): steps that took longer than a step's period of wall time
  /// (the step too slow for real time, or its thread taken off the core while stepping) ...
  std::int64_t overruns_long = 0;
  /// ... and steps that took less but began late, after a step that was on time: the thread woken
  /// late from its sleep to the deadline (a real-time priority helps: RunOptions::realtime_priority),
  /// or held up between steps (RunOptions::on_step). The rest followed a late step (catching up).
  std::int64_t overruns_began_late = 0;
  double max_lateness_ms = 0;  ///< how far past its deadline the latest step ended
  double wall_s = 0;           ///< wall-clock time of the run
  double simulated_s = 0;      ///< simulated time covered
  double realtime_factor = 0;  ///< simulated_s / wall_s

  /// A human-readable block of lines.
  std::string str() const;
};

/// Collects StepTiming samples in a ring allocated once, when it is made, and filled as steps are
/// recorded (its memory is touched then, not when it is made: an environment that takes few steps
/// does not pay for 16 MiB of zeros): recording a step never allocates, however long the run. When the ring is full the
/// oldest sample is overwritten, so summaries and CSV cover the newest `capacity()` steps. Not thread-safe; written by
/// the thread that steps.
class SSX_EXPORT TimingRecorder {
 public:
  /// 262,144 samples (16 MiB): 4.4 minutes at 1 kHz, 87 minutes at 50 Hz.
  static constexpr std::size_t kDefaultCapacity = std::size_t{1} << 18;
  /// A recorder keeping the newest `capacity` samples (at least 1), allocated now.
  explicit TimingRecorder(std::size_t capacity = kDefaultCapacity);
  /// Records one step's timing (overwriting the oldest when full). Never allocates.
  void add(const StepTiming& sample) noexcept;
  /// Forgets every sample (the ring stays allocated).
  void clear() noexcept;
  /// Samples kept (at most capacity()).
  std::size_t size() const noexcept { return size_; }
  /// Samples the ring holds at most.
  std::size_t capacity() const noexcept { return ring_.capacity(); }
  /// Samples added since construction or clear(), kept or not: a mark for summary().
  std::int64_t recorded() const noexcept { return recorded_; }
  /// The i-th kept sample, oldest first.
  const StepTiming& operator[](std::size_t i) const noexcept { return ring_[(head_ + ring_.size() - size_ + i) % ring_.size()]; }
  /// A copy of the kept samples, oldest first.
  std::vector<StepTiming> samples() const;
  /// Summary of the steps recorded at or after the mark `since` (a recorded() value; 0: all):
  /// `steps` counts all of them, the times cover those still kept (`timed_steps`); `wall` and
  /// `simulated` fill the rate fields; `overruns` counts kept samples with lateness > 0.
  TimingSummary summary(Nanoseconds wall = 0, Nanoseconds simulated = 0, std::int64_t since = 0) const;
  /// The newest sample, for the run loop to fill in lateness; nullptr when empty.
  StepTiming* last() noexcept { return size_ == 0 ? nullptr : &ring_[(head_ + ring_.size() - 1) % ring_.size()]; }
  /// Writes the kept samples as CSV with a header (times in nanoseconds).
  void writeCsv(std::ostream& out) const;
  /// Same, to a file; throws Error if it cannot be written to the end.
  void writeCsv(const std::string& path) const;

 private:
  std::vector<StepTiming> ring_;  ///< reserved for the capacity; grows into it, then wraps
  std::size_t head_ = 0;  ///< where the next sample goes
  std::size_t size_ = 0;
  std::int64_t recorded_ = 0;
};

}  // namespace ssx
