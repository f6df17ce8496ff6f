// The environment: its extensions, shared values, measurement callbacks, setup rules, settings and time.
#include "scene_util.hpp"
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

namespace {

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

TEST_CASE("contacts: two boxes stacked on the ground, each pair once with the impulse that holds the weight",
          "[environment]") {
  for (const std::string engine : {"ode", "bullet"}) {
    CAPTURE(engine);
    auto boxes = [&] {
      return loadSceneFromString("<scene><environment timestep=\"0.002\" threads=\"2\"/><physics engine=\"" + engine +
                                     "\"/><type name=\"box\" file=\"" + (ssx::test::kArtifacts / "box.xml").string() +
                                     "\"/><ground/><artifact type=\"box\" name=\"low\" xyz=\"0 0 0.1\"/>"
                                     "<artifact type=\"box\" name=\"high\" xyz=\"0 0 0.3\"/></scene>",
                                 "boxes.xml", ssx::test::kArtifacts);
    };
    Scene s = boxes(), unrecorded = boxes();
    Environment& env = *s.environment;
    CHECK_THROWS_WITH(env.contacts(), Catch::Contains("call recordContacts(true)"));
    env.recordContacts();
    env.step(500);  // 1 s: settled
    unrecorded.environment->step(500);
    CHECK(env.stateHash() == unrecorded.environment->stateHash());  // recording changes no bit
    const std::vector<EngineContact> contacts = env.contacts();
    REQUIRE(contacts.size() == 2);
    const int low = env.findArtifact("low")->root().bodyIndex(), high = env.findArtifact("high")->root().bodyIndex();
    CHECK(&env.bodyOwner(low) == env.findArtifact("low"));
    const double step_weight = 9.81 * 0.002;  // N s per kg over one step
    // low on the ground (the static world first), then high on low
    CHECK(contacts[0].body_a == low);
    CHECK(contacts[0].body_b == -1);
    CHECK(contacts[0].normal.z() > 0.99);  // from the ground up into the low box
    CHECK(contacts[0].impulse == Approx(2 * step_weight).epsilon(0.05));
    CHECK(contacts[0].position.z() == Approx(0.0).margin(0.01));
    CHECK(contacts[1].body_a == low);
    CHECK(contacts[1].body_b == high);
    CHECK(contacts[1].normal.z() < -0.99);  // from the high box down into the low one
    CHECK(contacts[1].impulse == Approx(step_weight).epsilon(0.05));
    // kept across an engine switch; emptied by a restore; gone when recording stops
    const std::vector<std::byte> state = env.saveState();
    env.switchPhysics(engine == "ode" ? "bullet" : "ode");
    env.step(1);
    CHECK(env.contacts().size() == 2);
    env.restoreState(state);
    CHECK(env.contacts().empty());
    env.recordContacts(false);
    CHECK_THROWS_AS(env.contacts(), Error);
  }
}

TEST_CASE("contacts: a box pushed into a wall on the ground says which static artifact each contact is with",
          "[environment]") {
  for (const std::string engine : {"ode", "bullet"}) {
    CAPTURE(engine);
    Scene s = loadSceneFromString("<scene><environment timestep=\"0.002\"/><physics engine=\"" + engine +
                                      "\"/><type name=\"box\" file=\"" + (ssx::test::kArtifacts / "box.xml").string() +
                                      "\"/><ground/><obstacle name=\"wall\" xyz=\"0.2 0 0.5\"><box size=\"0.1 1 1\"/>"
                                      "</obstacle><artifact type=\"box\" name=\"b\" xyz=\"0 0 0.1\"/></scene>",
                                  "wall.xml", ssx::test::kArtifacts);
    Environment& env = *s.environment;
    env.recordContacts();
    env.step(50);  // settled on the ground
    const int b = env.findArtifact("b")->root().bodyIndex();
    BodyState pushed = env.bodyState(b);
    pushed.linear_velocity = Vec3(2, 0, 0);  // towards the wall, 5 cm away (friction would stop it 20 cm on)
    env.setBodyState(b, pushed);
    std::vector<EngineContact> both;
    for (int k = 0; k < 200 && both.size() != 2; ++k) {
      env.step();
      both = env.contacts();
    }
    REQUIRE(both.size() == 2);
    // one record per static artifact touched, in the order they were added: the ground, the wall
    CHECK(both[0].body_b == -1);
    CHECK(both[1].body_b == -1);
    CHECK(both[0].static_group != both[1].static_group);
    CHECK(env.contactOther(both[0]).name() == "ground");
    CHECK(env.contactOther(both[1]).name() == "wall");
    CHECK(both[0].normal.z() > 0.99);   // up, from the ground into the box
    CHECK(both[1].normal.x() < -0.99);  // back, from the wall into the box
    CHECK(both[1].impulse > 0);
    CHECK(&env.contactOther(EngineContact{b, -1, {}, {}, 0, both[0].static_group}) == env.findArtifact("ground"));
    CHECK_THROWS_AS(env.contactOther(EngineContact{b, -1, {}, {}, 0, 7}), std::out_of_range);
  }
}
