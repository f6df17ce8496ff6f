// A step's phases (step_phases.cpp): sensors, drivers, the checks between them and physics, extension hooks,
// and how a failure in any of them is reported.
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

using namespace ssx;
using ssx::test::addBall;
using ssx::test::at;
using ssx::test::Counter;
using ssx::test::CountingSensor;
using ssx::test::LambdaDriver;
using ssx::test::ThrowingSensor;

TEST_CASE("a throwing driver abandons the step with a StepError naming artifact and plugin", "[environment]") {
  for (int threads : {1, 2}) {
    EnvironmentSettings s;
    s.threads = threads;
    Environment env(s);
    for (int i = 0; i < 20; ++i) {
      Artifact& a = addBall(env, "robot" + std::to_string(i), i);
      a.setDriver(std::make_unique<LambdaDriver>([i](Driver&, const StepInfo& info) {
                    if (info.step == 4 && (i == 7 || i == 13)) throw std::runtime_error("controller diverged");
                  }),
                  {}, 1, "my_controller");
    }
    env.step(4);
    try {
      env.step();
      FAIL("no StepError");
    } catch (const StepError& e) {
      // the lowest failing artifact is reported, whatever the threads
      CHECK(e.artifact() == "robot7");
      CHECK(e.plugin() == "driver 'my_controller'");
      CHECK(e.step() == 4);
      CHECK_THAT(e.what(), Catch::Contains("controller diverged"));
    }
    CHECK(env.state() == Environment::State::Failed);
    CHECK_THROWS_WITH(env.step(), Catch::Contains("failed in an earlier step"));
  }
}

TEST_CASE("a throwing sensor is named with its index and class", "[environment]") {
  Environment env;
  Artifact& a = addBall(env, "scout");
  a.addSensor(std::make_unique<CountingSensor>(), {}, 1, "clock");
  a.addSensor(std::make_unique<ThrowingSensor>(), {}, 1, "lidar");
  env.step(2);
  try {
    env.step();
    FAIL("no StepError");
  } catch (const StepError& e) {
    CHECK(e.artifact() == "scout");
    CHECK(e.plugin() == "sensor 1 'lidar'");
    CHECK_THAT(e.what(), Catch::Contains("lidar unplugged") && Catch::Contains("sensors phase"));
  }
}

TEST_CASE("a sensor writing a NaN into its measurement is stopped by name before anyone reads it", "[environment]") {
  // a pose sensor whose velocity becomes NaN at step 3 (a division by a zero time, say)
  class BrokenPose final : public SensorOf<PoseMeasurement> {
   public:
    void sense(const StepInfo& info) override {
      output().stamp = info.time;
      output().linear_velocity.x() = info.step == 3 ? std::numeric_limits<double>::quiet_NaN() : 1.0;
    }
  };
  Environment env;
  Artifact& a = addBall(env, "scout");
  Sensor& pose = a.addSensor(std::make_unique<BrokenPose>(), {}, 1, "mocap");
  Artifact& b = addBall(env, "listener", 2);
  std::vector<double> delivered;
  env.subscribe<PoseMeasurement>(pose, b, [&](const PoseMeasurement& m) { delivered.push_back(m.linear_velocity.x()); });
  env.step(3);
  CHECK(delivered == std::vector<double>{1.0, 1.0, 1.0});
  try {
    env.step();
    FAIL("no StepError");
  } catch (const StepError& e) {
    CHECK(e.artifact() == "scout");
    CHECK(e.plugin() == "sensor 0 'mocap'");
    CHECK(e.step() == 3);
    CHECK_THAT(e.what(), Catch::Contains("NaN or infinite") && Catch::Contains("sensors phase"));
  }
  CHECK(delivered.size() == 3);  // the NaN never reached a subscriber
  CHECK(env.state() == Environment::State::Failed);
}

TEST_CASE("a driver producing a NaN force is stopped by name", "[environment]") {
  Environment env;
  Artifact& a = addBall(env, "quad3");
  a.setDriver(std::make_unique<LambdaDriver>([](Driver& d, const StepInfo& info) {
                const double bad = info.step == 10 ? std::numeric_limits<double>::quiet_NaN() : 0.0;
                d.artifact().root().addForce(Vec3(0, 0, bad));
              }),
              {}, 1, "broken_pid");
  env.step(10);
  try {
    env.step();
    FAIL("no StepError");
  } catch (const StepError& e) {
    CHECK(e.artifact() == "quad3");
    CHECK(e.plugin() == "driver 'broken_pid'");
    CHECK_THAT(e.what(), Catch::Contains("NaN"));
  }
}

TEST_CASE("a driver's force or torque beyond the speed guards for one step is refused before physics", "[environment]") {
  // the engine would meet speeds it cannot integrate (ODE asserts inside its step); the run stops
  // naming the driver instead
  Environment env;
  Artifact& a = addBall(env, "spinner");
  a.setDriver(std::make_unique<LambdaDriver>([](Driver& d, const StepInfo& info) {
                d.artifact().root().addTorque(Vec3(0, 0, info.step == 3 ? 1e12 : 1.0));
              }),
              {}, 1, "wild_pid");
  env.step(3);
  try {
    env.step();
    FAIL("no StepError");
  } catch (const StepError& e) {
    CHECK(e.artifact() == "spinner");
    CHECK(e.plugin() == "driver 'wild_pid'");
    CHECK_THAT(e.what(), Catch::Contains("max_angular_speed"));
  }
}

TEST_CASE("a diverging state after physics is reported naming the artifact", "[environment]") {
  Environment env;
  addBall(env, "calm");
  Artifact& wild = addBall(env, "wild", 3);
  env.step();
  // non-finite or absurd inputs are refused where they are given
  CHECK_THROWS_WITH(wild.root().addForce(Vec3(std::numeric_limits<double>::infinity(), 0, 0)),
                    Catch::Contains("NaN or infinite"));
  CHECK_THROWS_WITH(wild.root().setVelocity(Vec3::Zero(), Vec3(1e200, 0, 0)), Catch::Contains("max_angular_speed"));
  // a finite but absurd force makes the body diverge in the physics step
  wild.root().addForce(Vec3(1e300, 0, 0));
  try {
    env.step();
    FAIL("no StepError");
  } catch (const StepError& e) {
    CHECK(e.artifact() == "wild");
    CHECK(e.plugin() == "physics");
    CHECK_THAT(e.what(), Catch::Contains("diverged"));
  }
  CHECK(env.state() == Environment::State::Failed);
}

TEST_CASE("a driver writing to another artifact is an error", "[environment]") {
  Environment env;
  Artifact& victim = addBall(env, "victim");
  Artifact& bully = addBall(env, "bully", 2);
  bully.setDriver(
      std::make_unique<LambdaDriver>([&victim](Driver&, const StepInfo&) { victim.root().addForce(Vec3(1, 0, 0)); }),
      {}, 1, "pusher");
  try {
    env.step();
    FAIL("no StepError");
  } catch (const StepError& e) {
    CHECK(e.artifact() == "bully");
    CHECK_THAT(e.what(), Catch::Contains("tried to write to artifact 'victim'"));
  }
}

TEST_CASE("drivers run at their period and hold their command in between", "[environment]") {
  EnvironmentSettings s;
  s.physics.gravity = Vec3::Zero();
  Environment env(s);
  Artifact& a = addBall(env, "slow");
  int runs = 0;
  a.setDriver(std::make_unique<LambdaDriver>([&runs](Driver& d, const StepInfo& info) {
                ++runs;
                CHECK(info.period == 5 * d.environment().timestep());
                d.artifact().root().addForce(Vec3(1, 0, 0));  // 1 N on 1 kg
              }),
              {}, 5);
  env.step(11);  // runs at steps 0, 5, 10
  CHECK(runs == 3);
  // the force written at step 0 acts in steps 1..10: 10 ms of 1 m/s^2
  CHECK(a.state().linear_velocity.x() == Approx(0.010).margin(1e-12));
}

TEST_CASE("substeps split the timestep", "[environment]") {
  // free fall with 4 substeps of h/4 equals 4x as many plain steps of h/4
  auto fall = [](int substeps, double dt, int steps) {
    EnvironmentSettings s;
    s.timestep = toNanoseconds(dt);
    s.physics.substeps = substeps;
    Environment env(s);
    Artifact& a = addBall(env, "a");
    env.step(steps);
    return a.pose().position.z();
  };
  CHECK(fall(4, 0.004, 100) == Approx(fall(1, 0.001, 400)).margin(1e-12));
  CHECK(fall(4, 0.004, 100) != Approx(fall(1, 0.004, 100)).margin(1e-9));
}

// what a plugin reaches is read-only unless it is its own to write: checked by the compiler
template <class T>
concept Pushable = requires(T& node) { node.addForce(Vec3(1, 0, 0)); };
template <class T>
concept Subscribable = requires(T& env, const Sensor& s, Artifact& a) { env.subscribe(s, a, [](const Measurement&) {}); };
static_assert(Pushable<PhysicNode> && !Pushable<const PhysicNode>);
static_assert(std::is_same_v<decltype(std::declval<Sensor&>().artifact()), const Artifact&>);
static_assert(std::is_same_v<decltype(std::declval<Driver&>().artifact()), Artifact&>);
static_assert(std::is_same_v<decltype(std::declval<const Artifact&>().root()), const PhysicNode&>);
static_assert(std::is_same_v<decltype(std::declval<Driver&>().environment()), const Environment&>);
static_assert(std::is_same_v<decltype(std::declval<const Environment&>().artifact(0)), const Artifact&>);
static_assert(std::is_same_v<decltype(std::declval<const Environment&>().physics()), const PhysicEngine&>);
static_assert(Subscribable<Environment> && !Subscribable<const Environment>);

TEST_CASE("sensors cannot write forces, even through a writable handle they were given", "[environment]") {
  // the types keep a sensor's own artifact read-only; a handle smuggled in is refused at run time
  struct Pushy : SensorOf<Counter> {
    Artifact* target = nullptr;
    void sense(const StepInfo&) override { target->root().addForce(Vec3(1, 0, 0)); }
  };
  Environment env;
  Artifact& a = addBall(env, "a");
  auto pushy = std::make_unique<Pushy>();
  pushy->target = &a;
  a.addSensor(std::move(pushy), {}, 1, "pushy");
  CHECK_THROWS_WITH(env.step(), Catch::Contains("a sensor tried to write to artifact 'a'"));
}

TEST_CASE("an extension that throws in a step hook stops the run naming it", "[environment]") {
  struct Flaky : SimulationExtension {
    void afterStep(Environment& env) override {
      if (env.stepCount() == 3) throw Error("bridge lost its peer");
    }
  };
  Environment env;
  addBall(env, "a");
  env.addExtension("bridge", std::make_unique<Flaky>());
  env.step(2);
  try {
    env.step();
    FAIL("no StepError");
  } catch (const StepError& e) {
    CHECK(e.plugin() == "extension 'bridge'");
    CHECK(e.step() == 2);
    CHECK_THAT(e.what(), Catch::Contains("afterStep: bridge lost its peer"));
  }
  CHECK(env.state() == Environment::State::Failed);
}

TEST_CASE("what only configure may do is refused from the parallel phases, with the reason", "[environment]") {
  // enabling neighbour queries, subscribing or asking for camera images from a driver's step would
  // change what other threads read in the same phase
  auto fromStep = [](std::function<void(Environment&, Driver&)> call) {
    EnvironmentSettings settings;
    settings.threads = 2;
    Environment env(settings);
    Artifact& a = addBall(env, "a");
    addBall(env, "b", 1).addSensor(std::make_unique<test::LambdaSensor>());
    a.setDriver(std::make_unique<LambdaDriver>([&env, call](Driver& d, const StepInfo&) { call(env, d); }));
    try {
      env.step();
    } catch (const StepError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(fromStep([](Environment& env, Driver&) { env.enableNeighborQueries(1.0); }),
             Catch::Contains("enableNeighborQueries is not allowed from a driver (the parallel phases)"));
  CHECK_THAT(fromStep([](Environment& env, Driver& d) {
               env.subscribe(env.findArtifact("b")->sensor(0), d.artifact(), [](const Measurement&) {});
             }),
             Catch::Contains("subscribe is not allowed from a driver"));
  Image image;
  CHECK_THAT(fromStep([&image](Environment& env, Driver&) {
               env.addCameraRequest("x", [](std::int64_t, CameraView&) { return false; }, image);
             }),
             Catch::Contains("addCameraRequest is not allowed from a driver"));
}
