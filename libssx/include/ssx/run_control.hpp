#pragma once
/// @file
/// RunControl: steering a run while it runs (pause, step, real-time factor, stop, tasks for the
/// stepping thread), from any thread.

#include <ssx/export.hpp>

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <vector>

namespace ssx {

class Environment;

/// A run steered while it runs, from any thread (a viewer's page, a program's UI): Environment::run
/// looks at it between steps. Pausing holds the run between two steps (and the stop flag still ends
/// it); on resuming, real time starts afresh from that moment (no catching up on the pause). A
/// step asked for while paused is taken at once. A real-time factor set here replaces the run's
/// from the next step on (real-time runs; a fast run ignores it).
class SSX_EXPORT RunControl {
 public:
  /// Holds the run after its current step.
  void pause();
  /// Lets a paused run go on.
  void resume();
  /// While paused: one more step (or n).
  void stepOnce(std::int64_t n = 1);
  /// The real-time factor of real-time runs from the next step on (kMinRealtimeFactor to
  /// kMaxRealtimeFactor; ConfigError otherwise).
  void setRealtimeFactor(double factor);
  /// Whether a pause was asked for.
  bool paused() const;
  /// The factor set, or 0 when none was (the run's own applies).
  double realtimeFactor() const;
  /// Ends run() between two steps (after the current one), as its stop flag would.
  void stop();
  /// Whether stop() was called (run() clears it when it returns).
  bool stopped() const;
  /// Work for the stepping thread between two steps (a ROS service call that reads or moves the
  /// world), from any thread: run() runs the tasks posted, in order, before each step and at once
  /// while paused; a program stepping with step() calls runPosted(). A task that throws ends run().
  void post(std::function<void()> task);
  /// Runs the tasks posted so far, on the calling thread; returns how many ran.
  std::size_t runPosted();

  /// For Environment::run: waits while paused (returns at once otherwise) until resumed, a step is
  /// asked for, `stop` is set or a task is posted (run it with runPosted() and wait again); returns
  /// true when a step may be taken.
  bool waitWhilePaused(const std::atomic<bool>* stop);

 private:
  friend class Environment;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool paused_ = false;
  bool stop_ = false;
  std::int64_t steps_ = 0;
  double factor_ = 0;
  std::vector<std::function<void()>> tasks_;
};

}  // namespace ssx
