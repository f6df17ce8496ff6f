#include "base/worker_pool.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <vector>

using ssx::detail::WorkerPool;

TEST_CASE("the worker pool covers every index exactly once", "[pool]") {
  for (unsigned threads : {1u, 2u, 4u}) {
    WorkerPool pool(threads);
    CHECK(pool.size() == threads);
    for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{1000}}) {
      for (int round = 0; round < 50; ++round) {
        std::vector<std::atomic<int>> hits(n);
        auto fn = [&](std::size_t b, std::size_t e) {
          for (std::size_t i = b; i < e; ++i) hits[i].fetch_add(1);
        };
        pool.parallelFor(n, 3, fn);
        for (std::size_t i = 0; i < n; ++i) REQUIRE(hits[i].load() == 1);
      }
    }
  }
}

TEST_CASE("the worker pool's guided chunks cover every index once and shrink to the least asked", "[pool]") {
  for (unsigned threads : {1u, 2u, 4u}) {
    WorkerPool pool(threads);
    for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{5}, std::size_t{1024}}) {
      for (int round = 0; round < 50; ++round) {
        std::vector<std::atomic<int>> hits(n);
        std::vector<std::size_t> sizes(n + 1, 0);  // by chunk start: its size
        auto fn = [&](std::size_t b, std::size_t e) {
          sizes[b] = e - b;
          for (std::size_t i = b; i < e; ++i) hits[i].fetch_add(1);
        };
        pool.parallelForGuided(n, 4, fn);
        for (std::size_t i = 0; i < n; ++i) REQUIRE(hits[i].load() == 1);
        if (n < 1024 || threads == 1) continue;
        // in index order: each chunk a share of what was left (1 / (2 x threads)), at least 4
        std::size_t at = 0;
        while (at < n) {
          const std::size_t want = std::min(n - at, std::max<std::size_t>(4, (n - at) / (2 * threads)));
          REQUIRE(sizes[at] == want);
          at += sizes[at];
        }
      }
    }
  }
  // the first chunk of 1,024 on 2 threads is a quarter of it, the last at most 4 (what was left)
  WorkerPool pool(2);
  std::vector<std::size_t> sizes;
  std::vector<std::size_t> starts;
  std::atomic_flag busy = ATOMIC_FLAG_INIT;
  auto record = [&](std::size_t b, std::size_t e) {
    while (busy.test_and_set()) {
    }
    starts.push_back(b);
    sizes.push_back(e - b);
    busy.clear();
  };
  pool.parallelForGuided(1024, 4, record);
  const auto first = std::find(starts.begin(), starts.end(), std::size_t{0}) - starts.begin();
  CHECK(sizes[static_cast<std::size_t>(first)] == 256);
  const auto last = std::max_element(starts.begin(), starts.end()) - starts.begin();
  CHECK(sizes[static_cast<std::size_t>(last)] <= 4);
}

TEST_CASE("the worker pool rethrows a task's exception after the barrier", "[pool]") {
  WorkerPool pool(3);
  std::atomic<int> done{0};
  auto fn = [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (i == 17) throw std::runtime_error("task 17");
      done.fetch_add(1);
    }
  };
  CHECK_THROWS_WITH(pool.parallelFor(100, 1, fn), "task 17");
  CHECK(done.load() == 99);  // every other chunk still ran
  // the pool is usable afterwards
  std::atomic<int> again{0};
  auto count = [&](std::size_t b, std::size_t e) { again.fetch_add(static_cast<int>(e - b)); };
  pool.parallelFor(100, 8, count);
  CHECK(again.load() == 100);
}

TEST_CASE("the worker pool does not wait for workers that have not joined a job", "[pool]") {
  // held workers stand for threads a virtual machine has not run yet when a job starts: the
  // caller does every chunk itself and returns (with a barrier for every worker, this hangs)
  WorkerPool pool(3, true);
  std::vector<int> hits(500, 0);
  auto fn = [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) ++hits[i];  // only the caller runs: no atomics needed
  };
  for (int round = 0; round < 3; ++round) pool.parallelFor(hits.size(), 7, fn);
  for (int h : hits) REQUIRE(h == 3);
  // released, they take part again, and every index is still covered once per job, also right
  // after they were woken ahead of it (as the real-time run loop does before a deadline)
  pool.releaseWorkers();
  for (int round = 0; round < 50; ++round) {
    if (round % 2 == 0) pool.wake();
    std::vector<std::atomic<int>> counted(1000);
    auto count = [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) counted[i].fetch_add(1);
    };
    pool.parallelFor(counted.size(), 3, count);
    for (const auto& c : counted) REQUIRE(c.load() == 1);
  }
}
