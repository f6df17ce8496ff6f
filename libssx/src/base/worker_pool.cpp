#include "base/worker_pool.hpp"

#include <chrono>

namespace ssx::detail {

namespace {
// Waking a sleeping thread costs tens of microseconds on a virtual machine, more than a small
// phase takes: a thread that has just finished, or the caller waiting for the others, first spins
// this long on the value it waits for, then sleeps.
constexpr auto kSpin = std::chrono::microseconds(50);
// after a job it did not join (woken ahead of one, or it came too late), a worker waits longer
// before it sleeps: the next job is due soon
constexpr auto kSpinAhead = std::chrono::microseconds(500);

constexpr std::uint64_t kClosed = std::uint64_t{1} << 32;
constexpr std::uint64_t kCount = kClosed - 1;
constexpr int kGenerationShift = 33;

template <class T>
void spinThenWait(const std::atomic<T>& value, T old, std::chrono::microseconds spin = kSpin) {
  const auto until = std::chrono::steady_clock::now() + spin;
  for (int k = 0; value.load(std::memory_order_acquire) == old; ++k) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
    if ((k & 63) == 63 && std::chrono::steady_clock::now() > until) {
      value.wait(old, std::memory_order_acquire);
      return;
    }
  }
}
}  // namespace

WorkerPool::WorkerPool(unsigned threads, bool held) : released_(!held) {
  const unsigned extra = threads > 1 ? threads - 1 : 0;
  workers_.reserve(extra);
  for (unsigned i = 0; i < extra; ++i) workers_.emplace_back([this] { workerLoop(); });
}

std::vector<std::thread::native_handle_type> WorkerPool::nativeHandles() {
  std::vector<std::thread::native_handle_type> out;
  for (auto& t : workers_) out.push_back(t.native_handle());
  return out;
}

void WorkerPool::wake() {
  if (workers_.empty()) return;
  // a job closed from the start: the workers wake, join nothing and spin for the next one
  const std::uint64_t generation = (generation_.load(std::memory_order_relaxed) + 1) & (kCount >> 1);
  job_.store((generation << kGenerationShift) | kClosed, std::memory_order_release);
  generation_.store(generation, std::memory_order_release);
  generation_.notify_all();
}

void WorkerPool::releaseWorkers() {
  released_.store(true, std::memory_order_release);
  released_.notify_all();
}

WorkerPool::~WorkerPool() {
  releaseWorkers();
  stop_.store(true, std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();
  for (auto& t : workers_) t.join();
}

void WorkerPool::work() {
  // take chunks until none are left
  const std::size_t share = 2 * std::size_t{size()};
  for (;;) {
    std::size_t begin = 0, end = 0;
    if (guided_) {
      begin = next_.load(std::memory_order_relaxed);
      do {
        if (begin >= n_) return;
        end = std::min(n_, begin + std::max(chunk_, (n_ - begin) / share));
      } while (!next_.compare_exchange_weak(begin, end, std::memory_order_relaxed));
    } else {
      begin = next_.fetch_add(chunk_, std::memory_order_relaxed);
      if (begin >= n_) break;
      end = std::min(n_, begin + chunk_);
    }
    try {
      invoke_(ctx_, begin, end);
    } catch (...) {
      if (!has_error_.exchange(true)) error_ = std::current_exception();
    }
  }
}

void WorkerPool::workerLoop() {
  released_.wait(false, std::memory_order_acquire);
  std::uint64_t seen = 0;
  bool joined = true;  // (the last job)
  for (;;) {
    spinThenWait(generation_, seen, joined ? kSpin : kSpinAhead);
    seen = generation_.load(std::memory_order_acquire);
    if (stop_.load(std::memory_order_relaxed)) return;
    // join the job of this generation, unless the caller has closed it (it finished without us)
    const std::uint64_t mine = seen << kGenerationShift;
    std::uint64_t job = job_.load(std::memory_order_acquire);
    joined = false;
    while (!joined && (job & ~kCount) == mine)
      joined = job_.compare_exchange_weak(job, job + 1, std::memory_order_acq_rel, std::memory_order_acquire);
    if (!joined) continue;
    work();
    // leaving: the caller waits for the count to reach 0 once it has closed the job
    if (((job_.fetch_sub(1, std::memory_order_acq_rel) - 1) & kClosed) != 0) job_.notify_one();
  }
}

void WorkerPool::run(std::size_t n, std::size_t chunk, Invoke invoke, void* ctx, bool guided) {
  if (n == 0) return;
  if (n <= chunk || workers_.empty()) {
    // one chunk: waking the workers would cost more than it saves
    invoke(ctx, 0, n);
    return;
  }
  n_ = n;
  chunk_ = chunk == 0 ? 1 : chunk;
  guided_ = guided;
  invoke_ = invoke;
  ctx_ = ctx;
  has_error_.store(false, std::memory_order_relaxed);
  error_ = nullptr;
  next_.store(0, std::memory_order_relaxed);
  // open the job (published before the generation that wakes the workers), then wake them
  const std::uint64_t generation = (generation_.load(std::memory_order_relaxed) + 1) & (kCount >> 1);
  job_.store(generation << kGenerationShift, std::memory_order_release);
  generation_.store(generation, std::memory_order_release);
  generation_.notify_all();
  work();
  // every chunk is taken: close the job to workers not yet in it, and wait for those inside
  for (std::uint64_t job = job_.fetch_or(kClosed, std::memory_order_acq_rel) | kClosed; (job & kCount) != 0;
       job = job_.load(std::memory_order_acquire))
    spinThenWait(job_, job);
  if (has_error_.load(std::memory_order_acquire)) std::rethrow_exception(error_);
}

}  // namespace ssx::detail
