// Environment::run: pacing steps against the monotonic clock.
#include <ssx/environment.hpp>

#include "base/worker_pool.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace ssx {

namespace {

Nanoseconds monotonicNow() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<Nanoseconds>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// sleeps until an absolute monotonic time, then spins for the last `spin` nanoseconds
void waitUntil(Nanoseconds deadline, Nanoseconds spin) {
  const Nanoseconds wake = deadline - spin;
  if (monotonicNow() < wake) {
    timespec ts{static_cast<time_t>(wake / 1'000'000'000), static_cast<long>(wake % 1'000'000'000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
  }
  while (monotonicNow() < deadline) {
  }
}

constexpr Nanoseconds kWakeAhead = 200'000;  // ns before a deadline the workers are woken

std::string describeSchedError(int error, int priority) {
  if (error == EPERM)
    return "SCHED_FIFO priority " + std::to_string(priority) +
           " is not permitted here: run as root, give the program CAP_SYS_NICE, or raise its real-time "
           "priority limit (ulimit -r; /etc/security/limits.conf)";
  return "SCHED_FIFO priority " + std::to_string(priority) + ": " + std::strerror(error);
}

// The threads of a run at a SCHED_FIFO priority, each put back to its own policy at the end,
// however the run ends.
class FifoScheduling {
 public:
  FifoScheduling(const std::vector<pthread_t>& threads, int priority) {
    for (pthread_t t : threads) {
      Saved saved{t, 0, {}};
      int error = pthread_getschedparam(t, &saved.policy, &saved.param);
      if (error == 0) {
        sched_param fifo{};
        fifo.sched_priority = priority;
        error = pthread_setschedparam(t, SCHED_FIFO, &fifo);
      }
      if (error != 0) {
        restore();
        throw Error("real-time priority: " + describeSchedError(error, priority));
      }
      saved_.push_back(saved);
    }
  }
  ~FifoScheduling() { restore(); }
  FifoScheduling(const FifoScheduling&) = delete;
  FifoScheduling& operator=(const FifoScheduling&) = delete;

 private:
  struct Saved {
    pthread_t thread;
    int policy;
    sched_param param;
  };
  void restore() noexcept {
    for (const Saved& s : saved_) pthread_setschedparam(s.thread, s.policy, &s.param);
    saved_.clear();
  }
  std::vector<Saved> saved_;
};

}  // namespace

std::string realtimePriorityProblem(int priority) {
  if (priority < kMinRealtimePriority || priority > kMaxRealtimePriority)
    return "the real-time priority must be from " + std::to_string(kMinRealtimePriority) + " to " +
           std::to_string(kMaxRealtimePriority);
  int error = 0;
  std::thread probe([&error, priority] {
    sched_param fifo{};
    fifo.sched_priority = priority;
    error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &fifo);
  });
  probe.join();
  return error == 0 ? std::string() : describeSchedError(error, priority);
}

void RunControl::pause() {
  std::lock_guard lock(mutex_);
  paused_ = true;
  changed_.notify_all();
}

void RunControl::resume() {
  std::lock_guard lock(mutex_);
  paused_ = false;
  steps_ = 0;
  changed_.notify_all();
}

void RunControl::stepOnce(std::int64_t n) {
  std::lock_guard lock(mutex_);
  if (paused_) steps_ += std::max<std::int64_t>(0, n);
  changed_.notify_all();
}

void RunControl::setRealtimeFactor(double factor) {
  if (!(factor >= kMinRealtimeFactor && factor <= kMaxRealtimeFactor))
    throw ConfigError({}, "real-time factor must be from 0.001 to 1e6");
  std::lock_guard lock(mutex_);
  factor_ = factor;
}

bool RunControl::paused() const {
  std::lock_guard lock(mutex_);
  return paused_;
}

double RunControl::realtimeFactor() const {
  std::lock_guard lock(mutex_);
  return factor_;
}

void RunControl::stop() {
  std::lock_guard lock(mutex_);
  stop_ = true;
  changed_.notify_all();
}

bool RunControl::stopped() const {
  std::lock_guard lock(mutex_);
  return stop_;
}

void RunControl::post(std::function<void()> task) {
  std::lock_guard lock(mutex_);
  tasks_.push_back(std::move(task));
  changed_.notify_all();
}

std::size_t RunControl::runPosted() {
  std::vector<std::function<void()>> now;
  {
    std::lock_guard lock(mutex_);
    if (tasks_.empty()) return 0;
    now.swap(tasks_);
  }
  // (outside the lock: a task may post, pause or step)
  for (std::size_t k = 0; k < now.size(); ++k) {
    try {
      now[k]();
    } catch (...) {
      // the ones after it stay posted, in order
      std::lock_guard lock(mutex_);
      tasks_.insert(tasks_.begin(), std::make_move_iterator(now.begin() + static_cast<std::ptrdiff_t>(k + 1)),
                    std::make_move_iterator(now.end()));
      throw;
    }
  }
  return now.size();
}

bool RunControl::waitWhilePaused(const std::atomic<bool>* stop) {
  std::unique_lock lock(mutex_);
  while (paused_ && steps_ == 0 && !stop_) {
    if (stop != nullptr && stop->load()) return false;
    if (!tasks_.empty()) {
      lock.unlock();
      runPosted();
      lock.lock();
      continue;
    }
    // (the stop flag is a plain atomic that nobody notifies: looked at every 20 ms)
    changed_.wait_for(lock, std::chrono::milliseconds(20));
  }
  if (stop_) return false;
  if (paused_) --steps_;
  return true;
}

TimingSummary Environment::run(const RunOptions& options) {
  if (options.mode == RunOptions::Mode::RealTime &&
      !(options.realtime_factor >= kMinRealtimeFactor && options.realtime_factor <= kMaxRealtimeFactor))
    throw ConfigError({}, "real-time factor must be from 0.001 to 1e6");
  const bool realtime = options.mode == RunOptions::Mode::RealTime;
  if (realtime && options.realtime_priority != 0 &&
      (options.realtime_priority < kMinRealtimePriority || options.realtime_priority > kMaxRealtimePriority))
    throw ConfigError({}, "real-time priority must be from " + std::to_string(kMinRealtimePriority) + " to " +
                              std::to_string(kMaxRealtimePriority) + " (0: off)");
  if (state() == State::Setup) start();
  // the stop flag, for plugins that wait (stopRequested), while this run runs
  struct StopFlag {
    std::atomic<const std::atomic<bool>*>& slot;
    StopFlag(std::atomic<const std::atomic<bool>*>& s, const std::atomic<bool>* flag) : slot(s) { slot = flag; }
    ~StopFlag() { slot = nullptr; }
    StopFlag(const StopFlag&) = delete;
    StopFlag& operator=(const StopFlag&) = delete;
  } stop_flag(run_stop_, options.stop);
  // wake within 1 ns of the deadline, not the default 50 us; the slack is the calling thread's,
  // so it is put back when the run ends, however it ends
  struct TimerSlack {
    long before = -1;
    explicit TimerSlack(bool tight) {
      if (!tight) return;
      before = prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0);
      if (before >= 0) prctl(PR_SET_TIMERSLACK, 1UL, 0, 0, 0);
    }
    ~TimerSlack() {
      if (before > 0) prctl(PR_SET_TIMERSLACK, static_cast<unsigned long>(before), 0, 0, 0);
    }
    TimerSlack(const TimerSlack&) = delete;
    TimerSlack& operator=(const TimerSlack&) = delete;
  } slack(realtime);
  // the stepping thread and the workers at a real-time priority, if asked
  std::optional<FifoScheduling> fifo;
  if (realtime && options.realtime_priority > 0) {
    std::vector<pthread_t> threads{pthread_self()};
    if (pool_ != nullptr)
      for (pthread_t t : pool_->nativeHandles()) threads.push_back(t);
    fifo.emplace(threads, options.realtime_priority);
  }

  RunControl& control = *run_control_;
  // (a stop() left from an earlier run is forgotten when this one ends)
  struct ClearStop {
    RunControl& c;
    ~ClearStop() {
      std::lock_guard lock(c.mutex_);
      c.stop_ = false;
    }
  } clear_stop{control};
  control.runPosted();  // (before the clock starts: what was asked before the first step)
  const std::int64_t first_sample = timing_.recorded();
  const std::int64_t first_step = stepCount();  // (steps are counted when no timing is kept too)
  const Nanoseconds sim_start = time();
  const Nanoseconds wall_start = monotonicNow();
  Nanoseconds grid_start = wall_start;  // deadlines are grid_start + k * period
  std::int64_t grid_k = 0;
  std::int64_t done = 0;
  std::int64_t overruns = 0, unreported = 0;
  std::int64_t overruns_long = 0, overruns_began_late = 0;
  bool previous_late = false;  // the step before ended past its deadline (and the grid was kept)
  Nanoseconds max_late = 0;
  Nanoseconds last_warning = wall_start - options.warn_interval;
  Nanoseconds worst_unreported = 0;

  double factor = realtime ? options.realtime_factor : 1.0;
  double period = static_cast<double>(settings_.timestep) / factor;
  while ((options.steps < 0 || done < options.steps) && !(options.stop != nullptr && options.stop->load())) {
    // steered from elsewhere (RunControl): posted tasks run here, a pause holds the run here (and
    // runs what is posted meanwhile); real time starts afresh after it, and a new factor takes over
    // from now
    control.runPosted();
    if (control.stopped()) break;
    const bool was_paused = control.paused();
    bool asked_while_paused = false;  // a step asked for while paused: taken at once, not paced
    if (was_paused) {
      if (!control.waitWhilePaused(options.stop)) break;
      asked_while_paused = control.paused();
    }
    const double asked = control.realtimeFactor();
    if (realtime && ((asked > 0 && asked != factor) || was_paused)) {
      if (asked > 0) factor = asked;
      period = static_cast<double>(settings_.timestep) / factor;
      grid_start = monotonicNow();
      grid_k = 0;
      previous_late = false;
    }
    step();
    ++done;
    ++grid_k;
    if (realtime && !asked_while_paused) {
      const Nanoseconds deadline =
          grid_start + static_cast<Nanoseconds>(std::llround(static_cast<double>(grid_k) * period));
      const Nanoseconds now = monotonicNow();
      if (now > deadline) {
        // overrun: record it, warn at most once per interval, and go on at once
        const Nanoseconds late = now - deadline;
        StepTiming* last = timing_.last();
        if (last != nullptr) last->lateness = late;
        max_late = std::max(max_late, late);
        // why: it took longer than a step, or it began late though the step before was on time
        if (last != nullptr && static_cast<double>(last->total) > period)
          ++overruns_long;
        else if (!previous_late)
          ++overruns_began_late;
        previous_late = options.overrun != RunOptions::Overrun::Resync;  // (a resync starts a new grid)
        ++overruns;
        ++unreported;
        worst_unreported = std::max(worst_unreported, late);
        if (now - last_warning >= options.warn_interval) {
          char msg[200];
          std::snprintf(
              msg, sizeof msg,
              "real time missed: %lld step(s) late since the last report, worst by %.3f ms (%lld overruns in all)",
              static_cast<long long>(unreported), static_cast<double>(worst_unreported) * 1e-6,
              static_cast<long long>(overruns));
          log(LogLevel::Warning, msg);
          last_warning = now;
          unreported = 0;
          worst_unreported = 0;
        }
        if (options.overrun == RunOptions::Overrun::Resync) {
          grid_start = now;
          grid_k = 0;
        }
      } else {
        previous_late = false;
        // the workers fall asleep between steps, and a woken thread can take a millisecond to
        // run on a virtual machine: they are woken a little ahead, so that the step finds them
        // running
        if (pool_ != nullptr && deadline - now > kWakeAhead) {
          waitUntil(deadline - kWakeAhead, 0);
          pool_->wake();
        }
        waitUntil(deadline, options.spin);
      }
    }
    if (options.on_step) options.on_step(*this);
  }
  // (the timing ring holds the newest steps; the overruns are counted over the whole run)
  TimingSummary summary = timing_.summary(monotonicNow() - wall_start, time() - sim_start, first_sample);
  summary.steps = stepCount() - first_step;
  summary.overruns = overruns;
  summary.max_lateness_ms = static_cast<double>(max_late) * 1e-6;
  summary.overruns_long = overruns_long;
  summary.overruns_began_late = overruns_began_late;
  return summary;
}

}  // namespace ssx
