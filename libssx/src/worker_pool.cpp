#include "worker_pool.hpp"

#include <chrono>

namespace ssx::detail {

namespace {
// Waking a sleeping thread costs tens of microseconds on a virtual machine, more than a small
// phase takes: a thread that has just finished, or the caller waiting for the others, first spins
// this long on the value it waits for, then sleeps.
constexpr auto kSpin = std::chrono::microseconds(50);

template <class T>
void spinThenWait(const std::atomic<T>& value, T old) {
  const auto until = std::chrono::steady_clock::now() + kSpin;
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

WorkerPool::WorkerPool(unsigned threads) {
  const unsigned extra = threads > 1 ? threads - 1 : 0;
  workers_.reserve(extra);
  for (unsigned i = 0; i < extra; ++i) workers_.emplace_back([this] { workerLoop(); });
}

WorkerPool::~WorkerPool() {
  stop_.store(true, std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();
  for (auto& t : workers_) t.join();
}

void WorkerPool::work() {
  // take chunks until none are left
  for (;;) {
    const std::size_t begin = next_.fetch_add(chunk_, std::memory_order_relaxed);
    if (begin >= n_) break;
    const std::size_t end = std::min(n_, begin + chunk_);
    try {
      invoke_(ctx_, begin, end);
    } catch (...) {
      if (!has_error_.exchange(true)) error_ = std::current_exception();
    }
  }
}

void WorkerPool::workerLoop() {
  std::uint64_t seen = 0;
  for (;;) {
    spinThenWait(generation_, seen);
    seen = generation_.load(std::memory_order_acquire);
    if (stop_.load(std::memory_order_relaxed)) return;
    work();
    // the last one out wakes the caller
    if (busy_.fetch_sub(1, std::memory_order_acq_rel) == 1) busy_.notify_one();
  }
}

void WorkerPool::run(std::size_t n, std::size_t chunk, Invoke invoke, void* ctx) {
  if (n == 0) return;
  if (n <= chunk || workers_.empty()) {
    // one chunk: waking the workers would cost more than it saves
    invoke(ctx, 0, n);
    return;
  }
  n_ = n;
  chunk_ = chunk == 0 ? 1 : chunk;
  invoke_ = invoke;
  ctx_ = ctx;
  has_error_.store(false, std::memory_order_relaxed);
  error_ = nullptr;
  next_.store(0, std::memory_order_relaxed);
  const unsigned workers = static_cast<unsigned>(workers_.size());
  if (workers > 0) {
    busy_.store(workers, std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
    generation_.notify_all();
  }
  work();
  // barrier: wait for every worker to finish its chunks
  for (unsigned left = busy_.load(std::memory_order_acquire); left != 0; left = busy_.load(std::memory_order_acquire))
    spinThenWait(busy_, left);
  if (has_error_.load(std::memory_order_acquire)) std::rethrow_exception(error_);
}

}  // namespace ssx::detail
