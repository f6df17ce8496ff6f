#include <ssx/error.hpp>
#include <ssx/timing.hpp>

#include <catch2/catch.hpp>

#include <sstream>

using namespace ssx;

TEST_CASE("timing summary percentiles use nearest rank", "[timing]") {
  TimingRecorder r;
  for (int i = 1; i <= 100; ++i) {
    StepTiming t;
    t.step = i - 1;
    t.total = i * 1'000'000;  // 1..100 ms
    t.physics = 500'000;
    t.lateness = i > 97 ? 1'000 : 0;
    r.add(t);
  }
  const TimingSummary s = r.summary(toNanoseconds(2.0), toNanoseconds(1.0));
  CHECK(s.steps == 100);
  CHECK(s.median_ms == Approx(50));
  CHECK(s.p95_ms == Approx(95));
  CHECK(s.p99_ms == Approx(99));
  CHECK(s.max_ms == Approx(100));
  CHECK(s.mean_ms == Approx(50.5));
  CHECK(s.physics_median_ms == Approx(0.5));
  CHECK(s.overruns == 3);
  // the recorder alone cannot tell why a step was late: the summary does not pretend to
  CHECK(s.overruns_long == 0);
  CHECK(s.overruns_began_late == 0);
  CHECK_THAT(s.str(), Catch::EndsWith("overruns 3 (max lateness 0.001 ms)"));
  CHECK(s.realtime_factor == Approx(0.5));
  CHECK(r.summary(0, 0, 90).steps == 10);
  CHECK(r.summary(0, 0, 90).median_ms == Approx(95));
}

TEST_CASE("timing samples are written as CSV", "[timing]") {
  TimingRecorder r;
  r.add({3, 10, 20, 30, 40, 0, 100, 5});
  std::ostringstream out;
  r.writeCsv(out);
  CHECK(out.str() ==
        "step,physics_ns,snapshot_ns,sensors_ns,drivers_ns,render_ns,total_ns,lateness_ns\n"
        "3,10,20,30,40,0,100,5\n");
  CHECK_THROWS_WITH(r.writeCsv("/nonexistent-dir/t.csv"), Catch::Contains("cannot write timing CSV"));
}

TEST_CASE("the recorder keeps the newest samples in a ring of fixed capacity", "[timing]") {
  TimingRecorder r(10);
  for (int i = 0; i < 25; ++i) r.add({i, 0, 0, 0, 0, 0, (i + 1) * 1'000'000, 0});
  CHECK(r.capacity() == 10);
  CHECK(r.size() == 10);
  CHECK(r.recorded() == 25);
  const std::vector<StepTiming> kept = r.samples();
  REQUIRE(kept.size() == 10);
  CHECK(kept.front().step == 15);  // oldest first
  CHECK(kept.back().step == 24);
  CHECK(r.last()->step == 24);
  // a mark taken before a run covers that run's samples only
  CHECK(r.summary(0, 0, 20).steps == 5);
  CHECK(r.summary(0, 0, 20).max_ms == Approx(25));
  // a mark older than the ring holds: every step is counted, the times are the kept ones
  CHECK(r.summary(0, 0, 3).steps == 22);
  CHECK(r.summary(0, 0, 3).timed_steps == 10);
  CHECK(r.summary().steps == 25);
  CHECK_THAT(r.summary().str(), Catch::Contains("steps 25,") && Catch::Contains("step time ms (of the newest 10 steps)"));
  CHECK(r.summary(0, 0, 20).timed_steps == 5);
  r.clear();
  CHECK(r.size() == 0);
  CHECK(r.last() == nullptr);
  CHECK(r.capacity() == 10);
}
