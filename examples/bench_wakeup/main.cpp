// ssx_bench_wakeup: how late this machine wakes a thread that sleeps until a deadline, without any
// simulation: what a real-time run's steps meet (ssx run --rt-priority).
//
// The calling thread works 0.7 ms, then sleeps to the next deadline of a 2 ms grid (absolute
// clock_nanosleep, 1 ns timer slack), 10,000 times, while a second thread runs (`--busy`: spins;
// else sleeps 1 ms at a time); prints how far past its deadline each wake-up came:
//   policy=other busy=0 wakeups=10000 median_us=28.1 p99_us=69.3 p999_us=1348.7 max_us=3914.5 over_1ms=10
// usage: ssx_bench_wakeup [--fifo P] [--busy] [--count N]
//   --fifo P  both threads at SCHED_FIFO priority P (1-99; needs root or CAP_SYS_NICE)
#include <ssx/ssx.hpp>

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace {

long long now() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<long long>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

bool setFifo(int priority) {
  sched_param p{};
  p.sched_priority = priority;
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  int fifo = 0, count = 10000;
  bool busy = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--fifo" && i + 1 < argc) {
      fifo = std::atoi(argv[++i]);
    } else if (a == "--count" && i + 1 < argc) {
      count = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--busy") {
      busy = true;
    } else {
      std::fprintf(stderr, "usage: ssx_bench_wakeup [--fifo P] [--busy] [--count N]\n");
      return 2;
    }
  }
  if (fifo != 0) {
    const std::string problem = ssx::realtimePriorityProblem(fifo);
    if (!problem.empty()) {
      std::fprintf(stderr, "ssx_bench_wakeup: --fifo %d: %s\n", fifo, problem.c_str());
      return 2;
    }
  }
  prctl(PR_SET_TIMERSLACK, 1UL, 0, 0, 0);  // this program's own thread: it is the benchmark
  if (fifo != 0 && !setFifo(fifo)) return 1;
  std::atomic<bool> stop{false};
  std::thread other([&] {
    if (fifo != 0) setFifo(fifo);
    while (!stop.load(std::memory_order_relaxed)) {
      if (busy) {
        const long long until = now() + 200'000;  // spin in slices, checking for the end
        while (now() < until) {
        }
      } else {
        timespec ms{0, 1'000'000};
        nanosleep(&ms, nullptr);
      }
    }
  });
  std::vector<long long> late;
  late.reserve(static_cast<std::size_t>(count));
  long long deadline = now();
  for (int k = 0; k < count; ++k) {
    const long long work_end = now() + 700'000;
    while (now() < work_end) {
    }
    deadline += 2'000'000;
    const timespec ts{static_cast<time_t>(deadline / 1'000'000'000), static_cast<long>(deadline % 1'000'000'000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
    }
    late.push_back(now() - deadline);
    if (late.back() > 2'000'000) deadline = now();  // a step late: start the grid again
  }
  stop = true;
  other.join();
  std::sort(late.begin(), late.end());
  auto at = [&](double q) { return static_cast<double>(late[static_cast<std::size_t>(q * (late.size() - 1))]) * 1e-3; };
  const auto over = std::count_if(late.begin(), late.end(), [](long long v) { return v > 1'000'000; });
  std::printf("policy=%s busy=%d wakeups=%d median_us=%.1f p99_us=%.1f p999_us=%.1f max_us=%.1f over_1ms=%lld\n",
              fifo != 0 ? "fifo" : "other", busy ? 1 : 0, count, at(0.5), at(0.99), at(0.999),
              static_cast<double>(late.back()) * 1e-3, static_cast<long long>(over));
  return 0;
}
