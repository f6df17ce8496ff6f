#pragma once
/// \file
/// The poses of a body measured outside the simulation (motion capture of a real robot), stamped in
/// simulated time, and the pose to use at a simulated time: interpolated between the samples
/// around it, extrapolated past the newest for at most a horizon, and lost when the samples stop
/// for longer than a timeout. The first part of real robots inside the simulation (ghost artifacts,
/// which the simulation will move by it).

#include <ssx/export.hpp>
#include <ssx/state.hpp>
#include <ssx/types.hpp>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

namespace ssx {

/// One body's stamped poses from outside, and the pose to use at a simulated time.
class SSX_EXPORT PoseStream {
 public:
  /// How far past the newest sample to extrapolate, when to call the body lost, how many samples to keep.
  struct Settings {
    double horizon = 0.05;      ///< s: past the newest sample, extrapolate at most this long, then hold
    double timeout = 0.5;       ///< s: with no sample this long, the body is lost
    std::size_t capacity = 64;  ///< samples kept (the oldest go first)
  };

  /// What to use at a simulated time.
  struct Estimate {
    Pose pose;                             ///< the pose to use
    Vec3 linear_velocity = Vec3::Zero();   ///< m/s, world frame (between the samples used)
    Vec3 angular_velocity = Vec3::Zero();  ///< rad/s, world frame
    double age = 0;                        ///< s: the time asked minus the newest sample's stamp at or before it
    bool extrapolated = false;             ///< past the newest sample (within the horizon, or held)
    bool lost = false;                     ///< no sample for longer than the timeout (the pose is the last known)
  };

  /// std::invalid_argument for a horizon or timeout that is negative or not finite, or capacity < 2.
  explicit PoseStream(const Settings& settings);
  PoseStream() : PoseStream(Settings{}) {}

  /// Adds a sample stamped `stamp` (simulated seconds). Samples may come out of order: each takes its
  /// place by stamp; one with a stamp already there replaces it. std::invalid_argument (nothing
  /// changed) for a non-finite stamp or pose, or an orientation far from unit length (normalised otherwise).
  void add(double stamp, const Pose& pose);
  /// The pose at simulated time `t`, or nothing before the first sample. Between two samples:
  /// position linear, orientation slerp. Before the oldest kept: the oldest. Past the newest: from the
  /// last two samples' velocities for at most `horizon`, then held (held at once when the last two
  /// are more than `timeout` apart); `lost` once t is more than `timeout` past the newest.
  std::optional<Estimate> at(double t) const;
  /// The same from the samples due by `t` (stamped at or before it): the next sample is
  /// interpolated towards only when it follows the newest due one within `timeout` (a replay fed
  /// ahead of time); one further ahead is held until t reaches it, so a pose stamped in the future
  /// does not move the body early, and the body is lost once the due samples are older than the
  /// timeout. `age` is t minus the newest due sample's stamp; nothing while no sample is due. What
  /// a ghost uses as the simulation steps.
  std::optional<Estimate> dueAt(double t) const;
  /// Positions farther than this from the origin on any axis are refused (m).
  static constexpr double kMaxCoordinate = 1e6;
  /// The samples kept.
  std::size_t size() const noexcept { return samples_.size(); }
  /// The newest stamp (no value before the first sample).
  std::optional<double> newest() const;
  /// What it was made with.
  const Settings& settings() const noexcept { return settings_; }

  /// The samples, for Environment::saveState: what `at` answers depends on nothing else.
  void saveState(StateWriter& out) const;
  /// Reads them back; StateError (nothing changed) for data that does not fit.
  void loadState(StateReader& in);

 private:
  struct Sample {
    double stamp;
    Pose pose;
  };
  Estimate fromNewest(std::size_t n, double t) const;
  static Estimate between(const Sample& a, const Sample& b, double t);
  Settings settings_;
  std::deque<Sample> samples_;  // by stamp, oldest first
};

/// The median and the 99th percentile of the ages of the poses used (seconds), for the summary of a run.
struct AgeSummary {
  std::size_t count = 0;  ///< ages summarised
  double median = 0;      ///< s
  double p99 = 0;         ///< s
  double max = 0;         ///< s
};

/// The ages of the poses used over a run, in bins of 0.1 ms up to 1 s (the memory a run needs does
/// not grow with its length): the median and p99 to the upper edge of their bin, the maximum exact.
class SSX_EXPORT AgeHistogram {
 public:
  static constexpr double kBinSeconds = 1e-4;   ///< width of a bin
  static constexpr std::size_t kBins = 10'000;  ///< bins; older ages go into the last
  /// Adds one age (s); a negative one counts as 0.
  void add(double age);
  /// The summary of the ages added (all zero when none were).
  AgeSummary summary() const;

 private:
  std::vector<std::uint64_t> bins_;
  std::size_t count_ = 0;
  double max_ = 0;
};

}  // namespace ssx
