#pragma once
// A fixed pool of worker threads for the parallel phases. The calling thread takes part; the
// workers that joined a job meet it at its end (a barrier). Work is handed out in chunks of
// indices from a shared counter, so a slow artifact does not hold up a whole thread's share, and a
// worker that wakes late (a virtual machine can take a millisecond to run a woken thread) finds
// the job done or closed and is not waited for: the caller has done its share.

#include <ssx/physic_engine.hpp>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <thread>
#include <vector>

namespace ssx::detail {

class WorkerPool final : public TaskRunner {
 public:
  /// `threads` in total, the caller included (>= 1); threads - 1 are started. With `held`, the
  /// workers take no job until releaseWorkers (as workers that wake late: for tests).
  explicit WorkerPool(unsigned threads, bool held = false);
  void releaseWorkers();
  ~WorkerPool() override;
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  unsigned size() const noexcept { return static_cast<unsigned>(workers_.size()) + 1; }
  /// The workers' threads (for their scheduling policy).
  std::vector<std::thread::native_handle_type> nativeHandles();
  /// Wakes the workers without a job, so that a job due shortly finds them running rather than
  /// asleep (from the thread that runs the jobs).
  void wake();

  // TaskRunner, for the physics engine: one task per index
  unsigned threads() const override { return size(); }
  void forEach(std::size_t n, void (*task)(void*, std::size_t), void* context) override {
    struct Each {
      void (*task)(void*, std::size_t);
      void* context;
    } each{task, context};
    run(
        n, 1,
        [](void* ctx, std::size_t b, std::size_t e) {
          auto& x = *static_cast<Each*>(ctx);
          for (std::size_t i = b; i < e; ++i) x.task(x.context, i);
        },
        &each);
  }

  /// Calls fn(begin, end) over [0, n) in chunks of `chunk`, on every thread; returns when all
  /// are done. If fn throws, the first exception caught is rethrown here after the barrier.
  template <class F>
  void parallelFor(std::size_t n, std::size_t chunk, F& fn) {
    run(
        n, chunk, [](void* ctx, std::size_t b, std::size_t e) { (*static_cast<F*>(ctx))(b, e); }, &fn);
  }
  /// As parallelFor, with chunks that shrink as the work runs out (guided scheduling): each takes
  /// a share of what is left, 1 / (2 x threads) of it, and at least `least`. Large chunks while
  /// there is much to do, and at the end no thread waits long for another's last chunk: for work
  /// whose indices cost about the same each and are many (the copies of a vector environment).
  template <class F>
  void parallelForGuided(std::size_t n, std::size_t least, F& fn) {
    run(
        n, least, [](void* ctx, std::size_t b, std::size_t e) { (*static_cast<F*>(ctx))(b, e); }, &fn, true);
  }

 private:
  using Invoke = void (*)(void*, std::size_t, std::size_t);
  void run(std::size_t n, std::size_t chunk, Invoke invoke, void* ctx, bool guided = false);
  void work();
  void workerLoop();

  std::vector<std::thread> workers_;
  std::atomic<std::uint64_t> generation_{0};
  // the current job: its generation (bits 33 and up), closed to joiners (bit 32), and how many
  // workers are inside it (bits 0-31)
  std::atomic<std::uint64_t> job_{0};
  std::atomic<std::size_t> next_{0};
  std::atomic<bool> stop_{false};
  std::atomic<bool> released_{true};
  std::size_t n_ = 0;
  std::size_t chunk_ = 1;
  bool guided_ = false;  // chunks of a share of what is left, at least chunk_
  Invoke invoke_ = nullptr;
  void* ctx_ = nullptr;
  std::atomic<bool> has_error_{false};
  std::exception_ptr error_;
};

}  // namespace ssx::detail
