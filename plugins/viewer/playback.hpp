#pragma once
// The clock of a recording played on the viewer's page (ssx replay --view): where in the recording
// the page is, moved on by the wall clock at a speed, paused, stepped one sample at a time, or sent
// to a time (the page's slider). Not thread-safe: the viewer holds its lock around it.
#include <ssx/types.hpp>

#include <cstddef>
#include <vector>

namespace ssx::viewer {

class Playback {
 public:
  static constexpr double kMinSpeed = 1.0 / 64, kMaxSpeed = 64;

  /// `times`: the recording's sample times, rising (at least one). Starts paused at the first.
  explicit Playback(std::vector<Nanoseconds> times);

  void pause() noexcept { paused_ = true; }
  /// Plays on from where it is; from the start again when it stood at the end.
  void resume() noexcept;
  /// While paused: the next sample (none past the last).
  void stepOnce() noexcept;
  /// Recorded seconds per wall-clock second, within [kMinSpeed, kMaxSpeed]; false (unchanged) outside.
  bool setSpeed(double speed) noexcept;
  /// To simulated time `t`, clamped to the recording; the sample at or before it is shown next.
  void seek(Nanoseconds t) noexcept;
  /// Moves on by `wall_seconds` of the wall clock (when playing); pauses at the last sample.
  void advance(double wall_seconds) noexcept;

  /// The sample to show: the last at or before time().
  std::size_t sample() const noexcept { return sample_; }
  Nanoseconds time() const noexcept { return time_; }
  bool paused() const noexcept { return paused_; }
  double speed() const noexcept { return speed_; }
  Nanoseconds start() const noexcept { return times_.front(); }
  Nanoseconds end() const noexcept { return times_.back(); }

 private:
  void settle() noexcept;  // sample_ from time_

  std::vector<Nanoseconds> times_;
  Nanoseconds time_ = 0;
  std::size_t sample_ = 0;
  double speed_ = 1;
  bool paused_ = true;
};

}  // namespace ssx::viewer
