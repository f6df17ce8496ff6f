#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

using namespace ssx;
using ssx::test::at;
using ssx::test::LambdaDriver;

namespace {

struct Counter : Measurement {
  int value = 0;
};

// a sensor that counts its own runs
class CountingSensor final : public SensorOf<Counter> {
 public:
  void sense(const StepInfo& info) override {
    output().value += 1;
    output().stamp = info.time;
  }
};

class ThrowingSensor final : public SensorOf<Counter> {
 public:
  void sense(const StepInfo& info) override {
    if (info.step == 2) throw std::runtime_error("lidar unplugged");
  }
};

// records init and shutdown calls into a shared journal
class JournalExtension final : public SimulationExtension {
 public:
  JournalExtension(std::string name, std::vector<std::string>& journal) : name_(std::move(name)), journal_(journal) {}
  void init(Environment& env, const Descriptor&) override {
    // engines are not configured yet
    journal_.push_back("init " + name_ + (env.state() == Environment::State::Setup ? " (setup)" : " (running?)"));
  }
  void shutdown(Environment& env) override {
    bool engines_gone = false;
    try {
      (void)env.physics();
    } catch (const Error&) {
      engines_gone = true;
    }
    journal_.push_back("shutdown " + name_ + (engines_gone ? " (engines stopped)" : " (engines alive!)"));
  }

 private:
  std::string name_;
  std::vector<std::string>& journal_;
};

Artifact& addBall(Environment& env, const std::string& name, double x = 0) {
  Artifact& a = env.addArtifact(name, at(x, 0, 1));
  a.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
  return a;
}

}  // namespace

TEST_CASE("extensions init before the engines and shut down after them, first in last out", "[environment]") {
  std::vector<std::string> journal;
  {
    Environment env;
    env.addExtension("a", std::make_unique<JournalExtension>("a", journal));
    env.addExtension("b", std::make_unique<JournalExtension>("b", journal));
    addBall(env, "ball");
    env.step();
    CHECK(journal == std::vector<std::string>{"init a (setup)", "init b (setup)"});
  }
  CHECK(journal == std::vector<std::string>{"init a (setup)", "init b (setup)", "shutdown b (engines stopped)",
                                            "shutdown a (engines stopped)"});
}

TEST_CASE("an extension that fails to init unwinds the ones before it", "[environment]") {
  struct Failing : SimulationExtension {
    void init(Environment&, const Descriptor&) override { throw Error("no ROS master"); }
  };
  std::vector<std::string> journal;
  Environment env;
  env.addExtension("a", std::make_unique<JournalExtension>("a", journal));
  env.addExtension("bad", std::make_unique<Failing>());
  CHECK_THROWS_WITH(env.start(), "no ROS master");
  CHECK(journal == std::vector<std::string>{"init a (setup)", "shutdown a (engines stopped)"});
  CHECK_THROWS(env.step());
}

TEST_CASE("drivers and sensors find extensions by name", "[environment]") {
  struct Bridge : SimulationExtension {
    int calls = 0;
  };
  Environment env;
  env.addExtension("bridge", std::make_unique<Bridge>());
  Artifact& a = addBall(env, "ball");
  Bridge* seen = nullptr;
  a.setDriver(std::make_unique<LambdaDriver>([&](Driver& d, const StepInfo&) {
    seen = d.environment().extension<Bridge>("bridge");
    seen->calls++;
  }));
  env.step(3);
  REQUIRE(seen != nullptr);
  CHECK(seen->calls == 3);
  CHECK(env.extension("nope") == nullptr);
}

namespace {
struct Gains {
  int made;
};
struct Other {
  int made;
};
// asks for a Gains under its key, and an Other under "a"; classes of two tags are two classes
template <int Tag>
class Asking final : public Driver {
 public:
  Asking(std::string key, int& made) : key_(std::move(key)), made_(made) {}
  void configure(const Descriptor&, PluginSetup& setup) override {
    gains = setup.shared<Gains>(key_, [&] { return Gains{++made_}; });
    other = setup.shared<Other>("a", [&] { return std::make_shared<Other>(Other{++made_}); });
  }
  void step(const StepInfo&) override {}
  std::shared_ptr<const Gains> gains;
  std::shared_ptr<const Other> other;

 private:
  std::string key_;
  int& made_;
};
}  // namespace

TEST_CASE("instances of a class that ask for the same value under the same key while starting share one, made once",
          "[environment]") {
  int made = 0;
  Environment env;
  std::vector<Asking<0>*> drivers;
  for (const char* key : {"a", "a", "b", "a"}) {
    auto d = std::make_unique<Asking<0>>(key, made);
    drivers.push_back(d.get());
    addBall(env, "ball" + std::to_string(drivers.size()), static_cast<double>(drivers.size())).setDriver(std::move(d));
  }
  // another class asking for the same types under the same keys gets values of its own
  auto stranger = std::make_unique<Asking<1>>("a", made);
  Asking<1>* other_class = stranger.get();
  addBall(env, "stranger", 9.0).setDriver(std::move(stranger));
  env.start();
  CHECK(made == 5);  // Gains "a", Other "a", Gains "b"; the other class's Gains "a" and Other "a"
  CHECK(drivers[0]->gains == drivers[1]->gains);
  CHECK(drivers[0]->gains == drivers[3]->gains);
  CHECK(drivers[2]->gains != drivers[0]->gains);
  CHECK(drivers[2]->gains->made == 3);
  CHECK(drivers[3]->other == drivers[0]->other);
  CHECK(other_class->gains->made == 4);
  CHECK(other_class->other->made == 5);
  // once started the environment holds none of them: the instances are the only owners
  CHECK(drivers[0]->gains.use_count() == 3);
  CHECK(drivers[2]->gains.use_count() == 1);
  CHECK(drivers[0]->other.use_count() == 4);
  CHECK(other_class->gains.use_count() == 1);
}

TEST_CASE("callbacks are delivered by source artifact, sensor and subscription, on every thread count",
          "[environment]") {
  for (int threads : {1, 2, 4}) {
    EnvironmentSettings s;
    s.threads = threads;
    Environment env(s);
    // three artifacts with two sensors each; artifact "sink" subscribes in a scrambled order
    std::vector<Artifact*> sources;
    for (int i = 0; i < 3; ++i) {
      Artifact& a = addBall(env, "src" + std::to_string(i), i);
      a.addSensor(std::make_unique<CountingSensor>(), {}, 1, "s0");
      a.addSensor(std::make_unique<CountingSensor>(), {}, 1, "s1");
      sources.push_back(&a);
    }
    Artifact& sink = addBall(env, "sink", 5);
    std::vector<std::string> order;
    auto record = [&order](std::string tag) { return [&order, tag](const Counter&) { order.push_back(tag); }; };
    env.subscribe<Counter>(sources[2]->sensor(1), sink, record("2.1"));
    env.subscribe<Counter>(sources[0]->sensor(1), sink, record("0.1a"));
    env.subscribe<Counter>(sources[1]->sensor(0), sink, record("1.0"));
    env.subscribe<Counter>(sources[0]->sensor(0), sink, record("0.0"));
    env.subscribe<Counter>(sources[0]->sensor(1), sink, record("0.1b"));
    env.step();
    CHECK(order == std::vector<std::string>{"0.0", "0.1a", "0.1b", "1.0", "2.1"});
  }
}

TEST_CASE("callbacks see this step's measurement and only from due sensors", "[environment]") {
  Environment env;
  Artifact& src = addBall(env, "src");
  auto& sensor = static_cast<CountingSensor&>(src.addSensor(std::make_unique<CountingSensor>(), {}, 3));
  Artifact& sink = addBall(env, "sink", 2);
  std::vector<std::pair<std::int64_t, int>> got;
  env.subscribe<Counter>(sensor, sink, [&](const Counter& c) { got.emplace_back(c.stamp, c.value); });
  env.step(7);
  // due at steps 0, 3, 6; stamps are the time after each of those steps' physics
  const Nanoseconds tau = env.timestep();
  CHECK(got == std::vector<std::pair<std::int64_t, int>>{{tau, 1}, {4 * tau, 2}, {7 * tau, 3}});
}

TEST_CASE("a callback that throws fails the step, naming its sensor and that sensor's artifact", "[environment]") {
  Environment env;
  Artifact& src = addBall(env, "src");
  src.addSensor(std::make_unique<CountingSensor>(), {}, 1, "s0");
  Sensor& second = src.addSensor(std::make_unique<CountingSensor>(), {}, 1, "s1");
  Artifact& sink = addBall(env, "sink", 2);
  env.subscribe<Counter>(second, sink, [](const Counter&) { throw std::runtime_error("no room"); });
  CHECK_THROWS_WITH(env.step(), Catch::Contains("callback subscribed to sensor 's1' of artifact 'src'") &&
                                    Catch::Contains("no room") && Catch::Contains("sink"));
}

TEST_CASE("subscribing with the wrong measurement type is refused", "[environment]") {
  struct Other : Measurement {};
  Environment env;
  Artifact& a = addBall(env, "a");
  Sensor& s = a.addSensor(std::make_unique<CountingSensor>());
  CHECK_THROWS_AS(env.subscribe<Other>(s, a, [](const Other&) {}), ConfigError);
}

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

TEST_CASE("setup calls are refused once running, and names are unique", "[environment]") {
  Environment env;
  addBall(env, "a");
  CHECK_THROWS_AS(env.addArtifact("a"), ConfigError);
  env.step();
  CHECK_THROWS_WITH(env.addArtifact("b"), Catch::Contains("only before the environment starts"));
  CHECK_THROWS(env.artifact(0).addSensor(std::make_unique<CountingSensor>()));
}

TEST_CASE("bad settings are refused at construction", "[environment]") {
  EnvironmentSettings s;
  s.timestep = 0;
  CHECK_THROWS_WITH(Environment(s), Catch::Contains("timestep must be positive"));
  s = {};
  s.physics.substeps = 0;
  CHECK_THROWS_AS(Environment(s), ConfigError);
  s = {};
  s.physics.engine = "physx";
  CHECK_THROWS_WITH(Environment(s), Catch::Contains("unknown physics engine 'physx'"));
}

TEST_CASE("time is an integer number of timesteps", "[environment]") {
  EnvironmentSettings s;
  s.timestep = 1'000'000 / 3;  // a timestep that is no round number of seconds
  Environment env(s);
  addBall(env, "a");
  env.step(3000);
  CHECK(env.time() == 3000 * s.timestep);
  CHECK(env.stepCount() == 3000);
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

TEST_CASE("frames are drawn when due, with render nodes following their physic nodes", "[environment][render]") {
  EnvironmentSettings s;
  s.render.period_steps = 5;
  Environment env(s);
  Artifact& a = addBall(env, "ball");
  RenderNodeSpec body;
  body.name = "shell";
  body.primitive = RenderNodeSpec::Primitive::Sphere;
  body.follow = "body";
  RenderNodeSpec mast;
  mast.name = "mast";
  mast.primitive = RenderNodeSpec::Primitive::Cylinder;
  mast.pose.position = Vec3(0, 0, 0.5);
  body.children.push_back(mast);
  a.addRenderRoot(body);
  RenderNodeSpec bad;
  bad.follow = "no_such_node";
  CHECK_THROWS_WITH(a.addRenderRoot(bad), Catch::Contains("follows unknown physic node 'no_such_node'"));

  env.step(12);  // due at steps 0, 5, 10; the null engine has no cameras to draw for
  CHECK(env.frameCount() == 0);
  CHECK(env.renderer().name() == "null");
  const auto& nodes = env.renderNodes();
  REQUIRE(nodes.size() == 2);
  CHECK(nodes[1].spec->name == "mast");
  CHECK(nodes[1].artifact == &a);
  // drawn at step 10: the mast sits 0.5 m above the falling body as it was then
  const double z_then = 1.0 - 9.81 * 0.001 * 0.001 * 11 * 12 / 2.0;
  CHECK(nodes[0].world.position.z() == Approx(z_then).margin(1e-9));
  CHECK(nodes[1].world.position.z() == Approx(z_then + 0.5).margin(1e-9));
  std::int64_t drawn = 0;
  for (const auto& t : env.timing().samples()) drawn += t.render > 0 ? 1 : 0;
  CHECK(drawn == 3);
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

TEST_CASE("plugins find the node a parameter names, or the first root", "[environment]") {
  Environment env;
  PhysicNodeSpec body = test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0);
  PhysicNodeSpec mount;
  mount.name = "imu_mount";
  mount.pose.position = Vec3(0.05, 0, 0);
  body.addChild(mount);
  Artifact& a = env.addArtifact("robot");
  a.addPhysicRoot(body);
  Descriptor none("sensor", {"robot.xml", 4});
  CHECK(&a.nodeFromParameter(none) == &a.root());
  Descriptor named("sensor", {"robot.xml", 4});
  named.set("node", "imu_mount");
  CHECK(a.nodeFromParameter(named).name() == "imu_mount");
  Descriptor wrong("sensor", {"robot.xml", 4});
  wrong.set("node", "imu_mnt", {"robot.xml", 5});
  CHECK_THROWS_WITH(a.nodeFromParameter(wrong),
                    "robot.xml:5: error: <sensor>: no physic node 'imu_mnt' in artifact 'robot'");
  Artifact& empty = env.addArtifact("logic");
  CHECK_THROWS_WITH(empty.nodeFromParameter(none), Catch::Contains("has no physic node"));
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

TEST_CASE("setBodyState moves a body between steps, in the engine and the snapshot", "[environment]") {
  EnvironmentSettings s;
  s.physics.gravity = Vec3::Zero();
  Environment env(s);
  Artifact& a = addBall(env, "a");
  Artifact& b = addBall(env, "b", 2);
  CHECK_THROWS_WITH(env.setBodyState(0, {}), Catch::Contains("not running"));
  env.step();
  BodyState teleport;
  teleport.pose.position = Vec3(5, -3, 2);
  teleport.pose.orientation = Quat(Eigen::AngleAxisd(0.5, Vec3::UnitZ()));
  teleport.linear_velocity = Vec3(1, 0, 0);
  env.setBodyState(a.root().bodyIndex(), teleport);
  // the snapshot shows it at once; the engine continues from it
  CHECK(a.pose().position == teleport.pose.position);
  CHECK(b.pose().position == Vec3(2, 0, 1));
  env.step(100);
  CHECK(a.pose().position.x() == Approx(5 + 100 * toSeconds(s.timestep)).epsilon(1e-9));
  CHECK(a.pose().position.y() == Approx(-3));
  CHECK(a.pose().orientation.angularDistance(teleport.pose.orientation) < 1e-9);
  CHECK(b.pose().position == Vec3(2, 0, 1));

  BodyState wild = teleport;
  wild.linear_velocity = Vec3(1e9, 0, 0);
  CHECK_THROWS_WITH(env.setBodyState(a.root().bodyIndex(), wild), Catch::Contains("max_linear_speed"));
  wild.linear_velocity = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  CHECK_THROWS_WITH(env.setBodyState(a.root().bodyIndex(), wild), Catch::Contains("finite"));
  CHECK_THROWS_WITH(env.setBodyState(7, teleport), Catch::Contains("no body 7 (there are 2)"));
  CHECK(a.pose().position.x() == Approx(5.1).epsilon(1e-9));  // the refused calls changed nothing

  // from a plugin's step it would race the other threads: refused with the reason
  Environment env2;
  Artifact& c = addBall(env2, "c");
  c.setDriver(std::make_unique<LambdaDriver>([&env2](Driver&, const StepInfo&) { env2.setBodyState(0, {}); }));
  CHECK_THROWS_WITH(env2.step(), Catch::Contains("setBodyState is not allowed from a driver"));
}
