// Engine factories: the engines a build offers, by name; an unknown name lists the ones there are;
// the null renderer draws nothing and says how to get images. What every engine must do alike:
// kinematic bodies (moved only by setState, infinitely heavy to what touches them).
#include "engine_util.hpp"
#include "scene_util.hpp"
#include "test_util.hpp"

#include <ssx/physic_engine.hpp>
#include <ssx/scene.hpp>
#include <ssx/render.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>

using namespace ssx;
using Catch::Contains;
using namespace ssx::test;

TEST_CASE("engines: every physics engine offered by name is made under that name", "[engines]") {
  const auto names = physicEngineNames();
  // the built-in ones first (a test below registers one of its own)
  REQUIRE(names.size() >= 2);
  CHECK(std::vector<std::string>(names.begin(), names.begin() + 2) == std::vector<std::string>{"ode", "bullet"});
  for (const auto& name : names) {
    PhysicsSettings settings;
    settings.engine = name;
    const auto engine = createPhysicEngine(settings);
    REQUIRE(engine != nullptr);
    CHECK(engine->name() == name);
  }
  PhysicsSettings wrong;
  wrong.engine = "physx";
  CHECK_THROWS_WITH(createPhysicEngine(wrong), Contains("unknown physics engine 'physx' (available: ode, bullet)"));
}

TEST_CASE("engines: the null renderer draws no pixels, unknown renderers list those there are", "[engines][render]") {
  const auto names = renderEngineNames();
  REQUIRE(std::find(names.begin(), names.end(), "null") != names.end());
  RenderSettings settings;
  const auto null = createRenderEngine(settings);
  CHECK(null->name() == "null");
  CHECK_FALSE(null->drawsPixels());
  Image image;
  CHECK_THROWS_WITH(null->renderView(CameraView{}, {}, Color{}, image), Contains("engine=\"osmesa\""));
  settings.engine = "vulkan";
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  CHECK_THROWS_WITH(createRenderEngine(settings), Contains("unknown render engine 'vulkan' (available: " + list + ")"));
}

TEST_CASE("engines: a kinematic body moves at its set velocity, whatever pushes it", "[engines][kinematic]") {
  const std::string name = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(name);
  auto engine = makeEngine(name);
  engine->addStatic({Shape::plane()}, Pose{});
  const int k = addBox(*engine, Vec3(0.5, 0.5, 0.5), 2.0, Vec3(0, 0, 0.2));  // in the ground: no contact
  const int other = addBox(*engine, Vec3(0.5, 0.5, 0.5), 2.0, Vec3(0.3, 0, 0.2));  // overlaps it
  engine->setKinematic(k);
  engine->setKinematic(other);
  CHECK(engine->isKinematic(k));
  CHECK_FALSE(engine->isKinematic(addBox(*engine, Vec3(0.1, 0.1, 0.1), 1.0, Vec3(5, 5, 5))));
  BodyState s;
  s.pose.position = Vec3(0, 0, 0.2);
  s.linear_velocity = Vec3(1, 0, 0);
  s.angular_velocity = Vec3(0, 0, 0.5);
  engine->setState(k, s);
  const std::vector<Wrench> push{{Vec3(100, 0, 0), Vec3(0, 0, 10)}, {Vec3(0, 100, 0), Vec3::Zero()}, {}};
  for (int i = 0; i < 100; ++i) engine->step(toNanoseconds(0.01), push);
  const auto now = states(*engine);
  CHECK(now[0].pose.position.x() == Approx(1.0).margin(1e-9));
  CHECK(now[0].pose.position.z() == Approx(0.2).margin(1e-12));  // no gravity, no ground
  CHECK(now[0].linear_velocity == Vec3(1, 0, 0));
  CHECK(now[0].angular_velocity == Vec3(0, 0, 0.5));
  const double yaw = 2 * std::atan2(now[0].pose.orientation.z(), now[0].pose.orientation.w());
  CHECK(yaw == Approx(0.5).margin(1e-6));
  CHECK(now[1].pose.position == Vec3(0.3, 0, 0.2));  // never set moving: still where it was
  CHECK(engine->contactCount() == 0);  // kinematic against static, kinematic against kinematic: nothing
}

TEST_CASE("engines: what rests on a kinematic platform is carried, what hits a kinematic wall stops, the wall does not",
          "[engines][kinematic]") {
  const std::string name = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(name);
  auto engine = makeEngine(name);
  const int platform = addBox(*engine, Vec3(1, 1, 0.1), 1.0, Vec3::Zero());
  const int load = addBox(*engine, Vec3(0.2, 0.2, 0.2), 10.0, Vec3(0, 0, 0.15));  // ten times the platform
  const int wall = addBox(*engine, Vec3(0.1, 2, 2), 0.1, Vec3(3, 0, 5));
  const int ball = addBox(*engine, Vec3(0.2, 0.2, 0.2), 50.0, Vec3(2.5, 0, 5));
  engine->setKinematic(platform);
  engine->setKinematic(wall);
  BodyState rising;
  rising.linear_velocity = Vec3(0, 0, 0.3);
  engine->setState(platform, rising);
  BodyState thrown;
  thrown.pose.position = Vec3(2.5, 0, 5);
  thrown.linear_velocity = Vec3(4, 0, 0);
  engine->setState(ball, thrown);
  std::vector<Wrench> hold(4);
  hold[static_cast<std::size_t>(ball)].force = Vec3(0, 0, 50 * 9.81);  // the ball flies level
  for (int i = 0; i < 500; ++i) engine->step(toNanoseconds(0.002), hold);
  const auto s = states(*engine);
  CHECK(s[static_cast<std::size_t>(platform)].pose.position.z() == Approx(0.3).margin(1e-9));
  CHECK(s[static_cast<std::size_t>(load)].pose.position.z() == Approx(0.45).margin(0.01));
  CHECK(s[static_cast<std::size_t>(load)].linear_velocity.z() == Approx(0.3).margin(0.03));
  CHECK(s[static_cast<std::size_t>(wall)].pose.position == Vec3(3, 0, 5));
  CHECK(s[static_cast<std::size_t>(ball)].pose.position.x() < 2.85 + 0.01);  // stopped at the wall's face
  CHECK(s[static_cast<std::size_t>(ball)].linear_velocity.x() < 0.1);
}

TEST_CASE("engines: an engine with kinematic bodies in contact restores and continues bitwise", "[engines][kinematic][state]") {
  const std::string name = GENERATE(as<std::string>{}, "ode", "bullet");
  INFO(name);
  auto build = [&] {
    auto e = makeEngine(name);
    e->addStatic({Shape::plane()}, Pose{});
    const int platform = addBox(*e, Vec3(1, 1, 0.1), 1.0, Vec3(0, 0, 0.3));
    e->setKinematic(platform);
    BodyState turning;
    turning.pose.position = Vec3(0, 0, 0.3);
    turning.angular_velocity = Vec3(0, 0, 1);
    e->setState(platform, turning);
    for (int i = 0; i < 4; ++i) addBox(*e, Vec3(0.15, 0.15, 0.15), 1.0, Vec3(0.3 * (i % 2) - 0.15, 0.3 * (i / 2) - 0.15, 0.5));
    return e;
  };
  const std::vector<Wrench> none(5);
  auto first = build();
  for (int k = 0; k < 200; ++k) first->step(toNanoseconds(0.002), none);
  const std::vector<std::byte> at200 = saved(*first);
  for (int k = 0; k < 200; ++k) first->step(toNanoseconds(0.002), none);
  auto second = build();
  StateReader in(at200);
  second->restoreState(in);
  for (int k = 0; k < 200; ++k) second->step(toNanoseconds(0.002), none);
  CHECK(saved(*second) == saved(*first));
  CHECK(first->contactCount() > 0);
  // the boxes turn with the platform (friction), the platform as set
  const auto s = states(*first);
  CHECK(s[0].angular_velocity == Vec3(0, 0, 1));
  CHECK(s[1].angular_velocity.z() == Approx(1).margin(0.1));
}

namespace {

// An engine of a program's own, registered from outside libssx: ODE with its clock scaled by the
// setting `time_scale` (what a slow-motion or a model-in-the-loop engine might do). Everything
// else is ODE's.
class TimeScaledEngine final : public PhysicEngine {
 public:
  explicit TimeScaledEngine(const PhysicsSettings& settings) : scale_(settings.options.get<double>("time_scale")) {
    PhysicsSettings ode = settings;
    ode.engine = "ode";
    ode.options = Descriptor();
    inner_ = createPhysicEngine(ode);
  }
  double scale() const { return scale_; }
  std::string name() const override { return "time_scaled"; }
  void setTaskRunner(TaskRunner* runner) override { inner_->setTaskRunner(runner); }
  int addBody(const MassProperties& m, const std::vector<Shape>& s, const BodyState& b) override { return inner_->addBody(m, s, b); }
  void setKinematic(int body) override { inner_->setKinematic(body); }
  bool isKinematic(int body) const override { return inner_->isKinematic(body); }
  void setMassScale(int body, double m, double i) override { inner_->setMassScale(body, m, i); }
  int addJoint(const EngineJoint& joint) override { return inner_->addJoint(joint); }
  void removeJoint(int joint) override { inner_->removeJoint(joint); }
  void setJointMotor(int joint, double v, double e) override { inner_->setJointMotor(joint, v, e); }
  std::size_t jointCount() const override { return inner_->jointCount(); }
  void prepareRayQueries() override { inner_->prepareRayQueries(); }
  void castRays(std::span<const Ray> r, std::span<RayHit> h, int b, int e) const override { inner_->castRays(r, h, b, e); }
  int addStatic(const std::vector<Shape>& shapes, const Pose& pose) override { return inner_->addStatic(shapes, pose); }
  void step(Nanoseconds dt, std::span<const Wrench> w) override {
    inner_->step(static_cast<Nanoseconds>(static_cast<double>(dt) * scale_), w);
  }
  void readStates(std::span<BodyState> out) const override { inner_->readStates(out); }
  void setState(int body, const BodyState& state) override { inner_->setState(body, state); }
  std::size_t bodyCount() const override { return inner_->bodyCount(); }
  std::size_t contactCount() const override { return inner_->contactCount(); }
  void recordContacts(bool on) override { inner_->recordContacts(on); }
  const std::vector<EngineContact>& contacts() const override { return inner_->contacts(); }
  void saveState(StateWriter& out) const override { inner_->saveState(out); }
  void restoreState(StateReader& in) override { inner_->restoreState(in); }

 private:
  double scale_;
  std::unique_ptr<PhysicEngine> inner_;
};

constexpr ssx_plugin_param kTimeScaled[] = {
    param::real("time_scale", "1", "", param::positive() & param::atMost(10), "simulated seconds per second of the world's clock"),
};

// registered once per process, as a program would at its start
void registerTimeScaled() {
  static const bool registered = [] {
    PhysicEngineClass c;
    c.name = "time_scaled";
    c.doc = "ODE with its clock scaled (a test)";
    c.settings.assign(std::begin(kTimeScaled), std::end(kTimeScaled));
    c.create = [](const PhysicsSettings& s) -> std::unique_ptr<PhysicEngine> { return std::make_unique<TimeScaledEngine>(s); };
    registerPhysicEngine(std::move(c));
    return true;
  }();
  (void)registered;
}

// how far a ball dropped at 1 m has fallen after `seconds`, in a scene on `physics`
double fallen(const std::string& physics, double seconds) {
  const std::string xml = "<scene><environment timestep=\"0.001\"/>" + physics +
                          "<type name=\"ball\" file=\"box.xml\"/><artifact name=\"b\" type=\"ball\" xyz=\"0 0 10\"/></scene>";
  Scene scene = loadSceneFromString(xml, "engine.xml", test::kArtifacts, testOptions());
  scene.environment->step(static_cast<std::int64_t>(seconds * 1000));
  return 10 - scene.environment->findArtifact("b")->pose().position.z();
}

}  // namespace

TEST_CASE("engines: a program's own engine, registered from outside libssx, is chosen and checked as the built-in ones",
          "[engines][registry]") {
  registerTimeScaled();
  const auto names = physicEngineNames();
  CHECK(std::find(names.begin(), names.end(), "time_scaled") != names.end());
  REQUIRE(findPhysicEngine("time_scaled") != nullptr);
  CHECK(findPhysicEngine("time_scaled")->settings.size() == 1);
  // a scene names it; its setting reaches it: half the clock, a quarter of the fall
  const double ode = fallen("", 1.0);
  const double slow = fallen(R"(<physics engine="time_scaled" time_scale="0.5"/>)", 1.0);
  CHECK(ode == Approx(0.5 * 9.81).epsilon(0.01));
  CHECK(slow == Approx(ode / 4).epsilon(0.02));
  CHECK(fallen(R"(<physics engine="time_scaled"/>)", 1.0) == ode);  // the default: 1, ODE's own bits
  // its setting is checked before anything runs, at the attribute's line, like a plugin's
  CHECK_THROWS_WITH(fallen(R"(<physics engine="time_scaled"
      time_scale="20"/>)", 1.0),
                    Contains("engine.xml:2: error: <physics>: time_scaled engine: parameter 'time_scale' must be"));
  // ODE's settings are not its own
  CHECK_THROWS_WITH(fallen(R"(<physics engine="time_scaled" partitions="4"/>)", 1.0),
                    Contains("attribute 'partitions' is an option of the ode engine, and the engine is 'time_scaled'"));
  // and its own are not ODE's
  CHECK_THROWS_WITH(fallen(R"(<physics time_scale="0.5"/>)", 1.0),
                    Contains("attribute 'time_scale' is an option of the time_scaled engine, and the engine is 'ode'"));
  // a model prints its settings, defaults filled in
  const SceneModel model = parseSceneString(R"(<scene><physics engine="time_scaled"/></scene>)", "m.xml", ".", {});
  CHECK_THAT(model.toXml(), Contains(R"(engine="time_scaled")") && Contains(R"(time_scale="1")"));
}

TEST_CASE("engines: a running environment switches to a registered engine, which starts from its own defaults",
          "[engines][registry]") {
  registerTimeScaled();
  Environment env(EnvironmentSettings{});
  addBall(env, "b");
  env.start();
  env.step(10);
  env.switchPhysics("time_scaled");
  env.step(10);
  CHECK(env.physics().name() == "time_scaled");
  CHECK(dynamic_cast<const TimeScaledEngine&>(env.physics()).scale() == 1.0);
  env.switchPhysics("ode");
  env.step(10);
  CHECK(env.physics().name() == "ode");
}

TEST_CASE("engines: registering refuses a taken name, a name that is no word, a missing create, a bad default",
          "[engines][registry]") {
  registerTimeScaled();
  PhysicEngineClass c;
  c.name = "time_scaled";
  c.create = [](const PhysicsSettings& s) -> std::unique_ptr<PhysicEngine> { return std::make_unique<TimeScaledEngine>(s); };
  CHECK_THROWS_WITH(registerPhysicEngine(c), Contains("'time_scaled' is registered already"));
  c.name = "Time Scaled";
  CHECK_THROWS_WITH(registerPhysicEngine(c), Contains("lower-case letters, digits and '_'"));
  c.name = "no_create";
  c.create = nullptr;
  CHECK_THROWS_WITH(registerPhysicEngine(c), Contains("no create function"));
  static constexpr ssx_plugin_param kBad[] = {param::real("k", "-1", "", param::positive(), "a gain")};
  c.name = "bad_default";
  c.create = [](const PhysicsSettings& s) -> std::unique_ptr<PhysicEngine> { return std::make_unique<TimeScaledEngine>(s); };
  c.settings.assign(std::begin(kBad), std::end(kBad));
  CHECK_THROWS_WITH(registerPhysicEngine(c), Contains("physics engine 'bad_default': ") && Contains("'k' must be > 0"));
  CHECK(findPhysicEngine("bad_default") == nullptr);
}
