#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <memory>

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>

using namespace ssx;

namespace {

double secondsOf(const std::function<void()>& fn) {
  const auto t0 = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Environment& withBall(Environment& env) {
  env.addArtifact("ball", test::at(0, 0, 1)).addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
  return env;
}

// busy-waits (no sleeping): the work a slow controller would do
void burn(std::chrono::microseconds d) {
  const auto until = std::chrono::steady_clock::now() + d;
  while (std::chrono::steady_clock::now() < until) {
  }
}

}  // namespace

TEST_CASE("real time paces 50 steps of 10 ms to at least 0.5 s, fast mode does not wait", "[run]") {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.010);
  Environment rt(s);
  withBall(rt);
  RunOptions o;
  o.steps = 50;
  TimingSummary summary;
  const double wall = secondsOf([&] { summary = rt.run(o); });
  CHECK(wall >= 0.5);
  CHECK(wall < 5.0);  // generous: a loaded CI machine
  CHECK(summary.steps == 50);
  CHECK(summary.simulated_s == Approx(0.5));
  CHECK(rt.stepCount() == 50);

  Environment fast(s);
  withBall(fast);
  o.mode = RunOptions::Mode::Fast;
  const double fast_wall = secondsOf([&] { fast.run(o); });
  CHECK(fast_wall < 0.5);
  CHECK(fast.stepCount() == 50);
}

TEST_CASE("a real-time factor scales the pacing", "[run]") {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.010);
  Environment env(s);
  withBall(env);
  RunOptions o;
  o.steps = 40;
  o.realtime_factor = 4.0;  // 0.4 s simulated in 0.1 s
  const double wall = secondsOf([&] { env.run(o); });
  CHECK(wall >= 0.1);
  CHECK(wall < 0.4);
}

TEST_CASE("overruns are counted and reported", "[run]") {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.001);
  s.threads = 1;
  Environment env(s);
  withBall(env);
  // every 5th step takes 3 ms of a 1 ms budget
  env.artifact(0).setDriver(std::make_unique<test::LambdaDriver>([](Driver&, const StepInfo& info) {
    if (info.step % 5 == 0) burn(std::chrono::microseconds(3000));
  }));
  std::vector<std::string> warnings;
  env.setLogSink([&](LogLevel level, std::string_view m) {
    if (level == LogLevel::Warning) warnings.emplace_back(m);
  });
  RunOptions o;
  o.steps = 20;
  o.warn_interval = 1'000'000'000;
  const TimingSummary summary = env.run(o);
  CHECK(summary.overruns >= 4);
  CHECK(summary.max_lateness_ms >= 1.5);
  // the 3 ms steps are the long ones (a step after one catches up: late, but not long)
  CHECK(summary.overruns_long >= 4);
  CHECK(summary.overruns_long + summary.overruns_began_late <= summary.overruns);
  CHECK_THAT(summary.str(), Catch::Contains(std::to_string(summary.overruns_long) + " took longer than a step"));
  // rate-limited: one warning in well under a second of run
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Contains("real time missed"));
}

TEST_CASE("a step that begins late after an on-time step is told from a long one", "[run]") {
  // steps of 20 ms that compute in microseconds; the program holds the loop up for 25 ms once,
  // between two steps: the next step begins 5 ms late (as after a late wake-up) and ends late,
  // and the one after it begins 15 ms before its deadline: on time again (margins wide enough for
  // a loaded machine: with 5 ms steps a sanitized run in parallel with others saw a second late one)
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.020);
  s.threads = 1;
  Environment env(s);
  withBall(env);
  env.setLogSink([](LogLevel, std::string_view) {});
  RunOptions o;
  o.steps = 10;
  o.on_step = [](const Environment& e) {
    if (e.stepCount() == 4) burn(std::chrono::microseconds(25000));
  };
  const TimingSummary summary = env.run(o);
  CHECK(summary.overruns_began_late >= 1);
  CHECK(summary.overruns - summary.overruns_long - summary.overruns_began_late == 0);  // none followed a late one
  CHECK_THAT(summary.str(), Catch::Contains("began late after an on-time step"));
}

TEST_CASE("catch-up keeps the original grid, resync restarts it", "[run]") {
  // one 30 ms step at the start of 20 steps of 2 ms: catch-up runs the next steps back to back
  // (40 ms in all), resync moves the grid and takes about 30 + 19 * 2 ms
  auto wallFor = [](RunOptions::Overrun policy, TimingSummary& summary) {
    EnvironmentSettings s;
    s.timestep = toNanoseconds(0.002);
    s.threads = 1;
    Environment env(s);
    withBall(env);
    env.artifact(0).setDriver(std::make_unique<test::LambdaDriver>([](Driver&, const StepInfo& info) {
      if (info.step == 0) burn(std::chrono::microseconds(30000));
    }));
    env.setLogSink([](LogLevel, std::string_view) {});
    RunOptions o;
    o.steps = 20;
    o.overrun = policy;
    double wall = 0;
    wall = secondsOf([&] { summary = env.run(o); });
    return wall;
  };
  TimingSummary catchup_summary, resync_summary;
  const double catchup = wallFor(RunOptions::Overrun::CatchUp, catchup_summary);
  const double resync = wallFor(RunOptions::Overrun::Resync, resync_summary);
  CHECK(catchup >= 0.040);
  CHECK(resync >= 0.030 + 19 * 0.002);
  // catch-up steps are late until the grid is reached: late for following a late step
  CHECK(catchup_summary.overruns > resync_summary.overruns);
  CHECK(catchup_summary.overruns_long >= 1);
  CHECK(catchup_summary.overruns - catchup_summary.overruns_long - catchup_summary.overruns_began_late >= 10);
  CHECK(resync_summary.overruns >= 1);
  CHECK(resync_summary.overruns_long >= 1);
}

TEST_CASE("a stop flag ends the run", "[run]") {
  Environment env;
  withBall(env);
  std::atomic<bool> stop{false};
  RunOptions o;
  o.mode = RunOptions::Mode::Fast;
  o.stop = &stop;
  o.on_step = [&stop](const Environment& e) {
    if (e.stepCount() == 123) stop = true;
  };
  env.run(o);
  CHECK(env.stepCount() == 123);
}

TEST_CASE("a real-time run leaves the calling thread's timer slack as it found it", "[run]") {
  // the library tightens the slack while it paces, and must not keep it so behind the program's back
  REQUIRE(prctl(PR_SET_TIMERSLACK, 123456UL, 0, 0, 0) == 0);
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.001);
  Environment env(s);
  withBall(env);
  RunOptions o;
  o.steps = 5;
  env.run(o);
  CHECK(prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0) == 123456);
  // also when the run ends by an exception
  o.on_step = [](const Environment&) { throw std::runtime_error("controller gave up"); };
  CHECK_THROWS_WITH(env.run(o), "controller gave up");
  CHECK(prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0) == 123456);
}

TEST_CASE("real-time factors outside 0.001 .. 1e6 are refused before anything runs", "[run]") {
  Environment env;
  withBall(env);
  RunOptions o;
  o.steps = 1;
  for (const double bad : {0.0, -1.0, 1e-300, 1e-4, 1e7, std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::quiet_NaN()}) {
    o.realtime_factor = bad;
    CHECK_THROWS_AS(env.run(o), ConfigError);
  }
  CHECK(env.stepCount() == 0);
}

TEST_CASE("times that do not fit 64-bit nanoseconds are refused, not wrapped", "[run]") {
  CHECK(toNanoseconds(1.5) == 1'500'000'000);
  CHECK(toNanoseconds(-2e-9) == -2);
  CHECK(toNanoseconds(9e9) == 9'000'000'000'000'000'000);
  for (const double bad : {1e300, -1e300, 9.3e9, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()})
    CHECK_THROWS_AS(toNanoseconds(bad), std::out_of_range);
}

TEST_CASE("a real-time run at a real-time priority steps every thread at it and puts each back", "[run]") {
  auto policyOf = [](pthread_t t) {
    int policy = -1;
    sched_param param{};
    REQUIRE(pthread_getschedparam(t, &policy, &param) == 0);
    return std::pair(policy, param.sched_priority);
  };
  const auto before = policyOf(pthread_self());
  REQUIRE(before.first != SCHED_FIFO);
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.005);
  s.threads = 2;
  Environment env(s);
  // drivers slow enough that both threads take chunks; each records the policy of its thread
  std::mutex mutex;
  std::map<pthread_t, std::pair<int, int>> seen;
  for (int i = 0; i < 16; ++i)
    env.addArtifact("ball" + std::to_string(i), test::at(i, 0, 1))
        .addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0))
        .artifact()
        .setDriver(std::make_unique<test::LambdaDriver>([&](Driver&, const StepInfo&) {
          burn(std::chrono::microseconds(100));
          int policy = -1;
          sched_param param{};
          pthread_getschedparam(pthread_self(), &policy, &param);
          const std::lock_guard<std::mutex> lock(mutex);
          seen[pthread_self()] = {policy, param.sched_priority};
        }));
  RunOptions o;
  o.steps = 40;
  o.realtime_priority = 7;
  std::pair<int, int> during{-1, -1};
  o.on_step = [&](const Environment&) { during = policyOf(pthread_self()); };
  const std::string problem = realtimePriorityProblem(7);
  if (!problem.empty()) {
    // not permitted here (no root, no CAP_SYS_NICE): refused with the reason, nothing changed
    INFO(problem);
    CHECK_THROWS_WITH(env.run(o), Catch::Contains("not permitted") || Catch::Contains("SCHED_FIFO"));
    CHECK(env.stepCount() == 0);
  } else {
    env.run(o);
    CHECK(during == std::pair(SCHED_FIFO, 7));
    REQUIRE(seen.size() == 2);  // the caller and the worker
    for (const auto& [thread, policy] : seen) CHECK(policy == std::pair(SCHED_FIFO, 7));
    // a fast run and a run without it leave the policies alone
    seen.clear();
    o.mode = RunOptions::Mode::Fast;
    env.run(o);
    CHECK(during == before);
    for (const auto& [thread, policy] : seen) CHECK(policy.first != SCHED_FIFO);
  }
  CHECK(policyOf(pthread_self()) == before);
  // out of range: refused before anything runs
  o.mode = RunOptions::Mode::RealTime;
  const std::int64_t steps = env.stepCount();
  for (const int bad : {-1, 100, 1000}) {
    o.realtime_priority = bad;
    CHECK_THROWS_AS(env.run(o), ConfigError);
  }
  CHECK(env.stepCount() == steps);
  CHECK_FALSE(realtimePriorityProblem(0).empty());
  CHECK_FALSE(realtimePriorityProblem(100).empty());
}

TEST_CASE("a run's summary counts every step even when the timing ring keeps only the newest", "[run]") {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.001);
  s.timing_samples = 16;
  Environment env(s);
  withBall(env);
  RunOptions o;
  o.mode = RunOptions::Mode::Fast;
  o.steps = 100;
  const TimingSummary summary = env.run(o);
  CHECK(summary.steps == 100);
  CHECK(summary.timed_steps == 16);
  CHECK_THAT(summary.str(), Catch::Contains("steps 100,") && Catch::Contains("(of the newest 16 steps)"));
  CHECK(env.timing().samples().size() == 16);
}

TEST_CASE("timing_samples = 0 keeps no timing and reads no clock in a step, and the run is the same bits", "[run]") {
  auto run = [](std::size_t samples) {
    EnvironmentSettings s;
    s.timestep = toNanoseconds(0.001);
    s.timing_samples = samples;
    auto env = std::make_unique<Environment>(s);
    withBall(*env);
    env->step(50);
    return env;
  };
  const auto untimed = run(0), timed = run(16);
  CHECK(untimed->timing().size() == 0);
  CHECK(untimed->timing().recorded() == 0);
  CHECK(timed->timing().size() == 16);
  CHECK(untimed->stateHash() == timed->stateHash());
  RunOptions o;
  o.mode = RunOptions::Mode::Fast;
  o.steps = 10;
  const TimingSummary summary = untimed->run(o);
  CHECK(summary.steps == 10);
  CHECK(summary.timed_steps == 0);
  INFO(summary.str());
  CHECK_THAT(summary.str(), Catch::Contains("steps 10,") && Catch::Contains("step times not kept") &&
                                !Catch::Contains("median"));
}

TEST_CASE("a run paused from another thread holds between steps, takes single steps, and resumes without catching up",
          "[run]") {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.002);
  Environment env(s);
  withBall(env);
  RunControl& control = env.runControl();
  std::atomic<std::int64_t> steps{0};
  std::atomic<bool> stop{false};
  RunOptions o;
  o.steps = 300;
  o.stop = &stop;
  o.on_step = [&](const Environment& e) {
    steps = e.stepCount();
    if (e.stepCount() == 50) control.pause();  // held after this step
  };
  TimingSummary summary;
  std::thread runner([&] { summary = env.run(o); });
  // held at 50: nothing moves while paused, however long one waits for it
  while (!control.paused()) std::this_thread::yield();
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(300);
  while (std::chrono::steady_clock::now() < until) CHECK(steps.load() == 50);
  // three single steps, taken at once
  control.stepOnce(3);
  while (steps.load() < 53) std::this_thread::yield();
  const auto hold = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
  while (std::chrono::steady_clock::now() < hold) CHECK(steps.load() == 53);
  // resumed: the other 247 steps take their 0.494 s of real time (no burst to catch up on the pause)
  double wall = 0;
  {
    const auto t0 = std::chrono::steady_clock::now();
    control.resume();
    runner.join();
    wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  CHECK(summary.steps == 300);
  CHECK(wall >= 0.494 * 0.99);
  CHECK(env.stepCount() == 300);
}

TEST_CASE("a real-time factor set from another thread paces the rest of the run", "[run]") {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.010);
  Environment env(s);
  withBall(env);
  RunOptions o;
  o.steps = 40;
  env.runControl().setRealtimeFactor(4.0);  // 0.4 s simulated in 0.1 s
  const double wall = secondsOf([&] { env.run(o); });
  CHECK(wall >= 0.1 * 0.99);
  CHECK(wall < 0.4);
  CHECK_THROWS_AS(env.runControl().setRealtimeFactor(0), ConfigError);
  // a stop while paused ends the run
  std::atomic<bool> stop{false};
  o.stop = &stop;
  o.steps = -1;
  env.runControl().pause();
  std::thread stopper([&] { stop = true; });
  env.run(o);
  stopper.join();
  CHECK(env.stepCount() == 40);
}

TEST_CASE("tasks posted from another thread run on the stepping thread between steps, in order, also while paused, "
          "stop() ends the run",
          "[run]") {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.002);
  Environment env(s);
  withBall(env);
  RunControl& control = env.runControl();
  std::atomic<std::int64_t> steps{0};
  std::atomic<bool> stop{false};  // (the test's bound only: stop() ends the run)
  RunOptions o;
  o.steps = -1;
  o.stop = &stop;
  o.on_step = [&](const Environment& e) { steps = e.stepCount(); };
  std::thread::id stepper;
  std::vector<std::int64_t> seen;  // the step count each task saw, in the order they ran
  std::mutex m;
  auto record = [&] {
    std::lock_guard lock(m);
    seen.push_back(env.stepCount());
    stepper = std::this_thread::get_id();
  };
  control.post(record);  // before the run: runs before its first step
  std::thread runner([&] { env.run(o); });
  auto waitFor = [](auto done) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!done() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return done();
  };
  auto count = [&] {
    std::lock_guard lock(m);
    return seen.size();
  };
  CHECK(waitFor([&] { return steps.load() >= 20; }));
  // while it plays: between two steps, on the stepping thread
  control.post(record);
  CHECK(waitFor([&] { return count() == 2; }));
  // while paused: at once, and the run stays where it was (the environment is read on its own
  // thread only: by the tasks)
  control.pause();
  for (int k = 0; k < 3; ++k) control.post(record);
  CHECK(waitFor([&] { return count() == 5; }));
  const std::int64_t held = steps.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  CHECK(steps.load() == held);
  control.post([&] { control.stop(); });
  runner.join();
  CHECK(stop.load() == false);
  std::lock_guard lock(m);
  REQUIRE(seen.size() == 5);
  CHECK(seen[0] == 0);
  CHECK(seen[1] >= 20);
  CHECK((seen[2] == held && seen[3] == held && seen[4] == held));
  CHECK(env.stepCount() == held);
  CHECK(stepper != std::this_thread::get_id());
  CHECK_FALSE(control.stopped());  // (forgotten when the run ended)

  // a task that throws ends the run; the ones after it stay posted, in order
  control.resume();
  std::vector<int> order;
  control.post([&] { throw std::runtime_error("task failed"); });
  control.post([&] { order.push_back(1); });
  control.post([&] { order.push_back(2); });
  o.steps = 10;
  CHECK_THROWS_WITH(env.run(o), "task failed");
  CHECK(order.empty());
  CHECK(control.runPosted() == 2);
  CHECK(order == std::vector<int>{1, 2});
}
