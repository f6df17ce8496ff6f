// The bridges' shared logic with a transport of the test's own: a message that cannot be used (not
// finite, absurd, a zero quaternion, a level the robot does not take) is dropped and counted, with
// a warning naming its topic the first time and a count per topic at the end; the run goes on and
// the robot keeps what it had.
#include "extension.hpp"

#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace ssx;
using namespace ssx::bridge;

namespace {

class FakeTransport final : public Transport {
 public:
  explicit FakeTransport(std::vector<RobotTopics> robots) : Transport(std::move(robots)) { startPublishing(); }
  ~FakeTransport() override { stopPublishing(); }
  using Transport::receivedJointCommand;
  using Transport::receivedJoy;
  using Transport::receivedSetpoint;
  using Transport::receivedVelocity;

 private:
  void send(const Outgoing&) override {}
  bool connected(std::size_t) const override { return true; }
};

class TestBridge final : public BridgeExtension {
 public:
  explicit TestBridge(bool transforms = false) : transforms_(transforms) {}
  FakeTransport* transport = nullptr;

 protected:
  std::unique_ptr<Transport> open(Environment&, const Descriptor&, const std::vector<RobotTopics>& robots) override {
    auto t = std::make_unique<FakeTransport>(robots);
    transport = t.get();
    return t;
  }
  void close(Transport&) override {}
  const char* name() const override { return "test"; }
  bool offersTransforms() const override { return transforms_; }

 private:
  bool transforms_;
};

const char* kScene = R"(<scene><environment timestep="0.002" seed="5"/><ground/>
  <type name="q" file="mk_quad.xml"/><type name="e" file="epuck.xml"/>
  <artifact name="q0" type="q" xyz="0 0 0.05"><driver offset="0 0 1"/></artifact>
  <artifact name="e0" type="e" xyz="2 0 0"/>
  <extension name="op" plugin="operator" robots="q0"/></scene>)";

// the bridge's parameters at their defaults, and `extra`
Descriptor bridgeParams(std::vector<std::pair<std::string, std::string>> extra = {}) {
  Descriptor d("extension", {});
  for (const auto& p : kBridgeParameters) d.set(p.name, p.default_value);
  for (const auto& [k, v] : extra) d.set(k, v);
  return d;
}

}  // namespace

TEST_CASE("bridges: a message that cannot be used is dropped and counted, the run goes on", "[bridge]") {
  Scene scene = loadSceneFromString(kScene, "bridge.xml", test::kArtifacts, test::testOptions());
  Environment& env = *scene.environment;
  std::vector<std::string> warnings;
  env.setLogSink([&](LogLevel level, std::string_view text) {
    if (level == LogLevel::Warning) warnings.emplace_back(text);
  });
  auto bridge = std::make_unique<TestBridge>();
  TestBridge& b = *bridge;
  env.addExtension("bridge", std::move(bridge), bridgeParams({{"operators", "op"}}));
  env.step(500);  // 1 s: q0 hovers at 1 m
  REQUIRE(b.transport != nullptr);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // q0 is robot 0, e0 robot 1, the operator 2 (after the robots)
  b.transport->receivedSetpoint(0, 0, {nan, 0, 1}, {1, 0, 0, 0});
  env.step(1);
  b.transport->receivedSetpoint(0, 0, {1e300, 0, 1}, {1, 0, 0, 0});
  env.step(1);
  b.transport->receivedSetpoint(0, 0, {0, 0, 1}, {0, 0, 0, 0});  // a zero quaternion
  env.step(1);
  b.transport->receivedVelocity(0, {1e300, 0, 0}, {0, 0, 0});
  env.step(1);
  b.transport->receivedVelocity(1, {nan, 0, 0}, {0, 0, 0});
  env.step(1);
  b.transport->receivedVelocity(2, {0, 0, 0}, {0, 0, std::numeric_limits<double>::infinity()});
  env.step(1);
  const float axes[4] = {std::numeric_limits<float>::quiet_NaN(), 0, 0, 0};
  b.transport->receivedJoy(2, 0, axes, 4, nullptr, 0);
  env.step(500);
  // the run went on: q0 still hovers where it was told before
  const Vec3 p = env.findArtifact("q0")->pose().position;
  CHECK(p.allFinite());
  CHECK(std::abs(p.z() - 1.0) < 0.05);
  CHECK(p.head<2>().norm() < 0.05);
  // one warning per topic the first time, naming it
  std::string all;
  for (const auto& w : warnings) all += w + "\n";
  INFO(all);
  CHECK_THAT(all, Catch::Contains("test: a message on /q0/setpoint was dropped (") &&
                      Catch::Contains("test: a message on /q0/cmd_vel was dropped (") &&
                      Catch::Contains("test: a message on /e0/cmd_vel was dropped (") &&
                      Catch::Contains("test: a message on /op/cmd_vel was dropped (") &&
                      Catch::Contains("test: a message on /op/joy was dropped ("));
  CHECK(warnings.size() == 5);
  // and a count per topic at the end
  warnings.clear();
  env.stop();
  std::string end;
  for (const auto& w : warnings) end += w + "\n";
  CHECK_THAT(end, Catch::Contains("test: 3 message(s) on /q0/setpoint dropped"));
  CHECK_THAT(end, Catch::Contains("test: 1 message(s) on /e0/cmd_vel dropped"));
  // and then good messages work again
}

TEST_CASE("bridges: a good message after bad ones is used", "[bridge]") {
  Scene scene = loadSceneFromString(kScene, "bridge.xml", test::kArtifacts, test::testOptions());
  Environment& env = *scene.environment;
  env.setLogSink([](LogLevel, std::string_view) {});
  auto bridge = std::make_unique<TestBridge>();
  TestBridge& b = *bridge;
  env.addExtension("bridge", std::move(bridge), bridgeParams());
  env.step(500);
  b.transport->receivedSetpoint(0, 0, {std::nan(""), 0, 1}, {1, 0, 0, 0});
  env.step(1);
  b.transport->receivedSetpoint(0, 0, {0.5, 0, 1}, {1, 0, 0, 0});
  env.step(1);
  const auto& tracker = dynamic_cast<const SetpointInterface&>(*env.findArtifact("q0")->driver());
  CHECK(tracker.currentSetpoint().position == Vec3(0.5, 0, 1));
  env.step(1500);
  CHECK(env.findArtifact("q0")->pose().position.x() > 0.4);  // on its way there
}

TEST_CASE("bridges: joint commands drive a robot's joints by name, a command naming a joint it lacks is dropped",
          "[bridge][joints]") {
  // the Husky from its URDF, no driver: its wheels (given motors here) take commands from outside
  const std::string scene_text = R"(<scene><environment timestep="0.002" seed="5"/><ground/>
    <type name="h" file=")" + std::string(SSX_EXAMPLES_DIR) + R"(/robots/husky/husky.urdf">
      <joint node="front_left_wheel_link" max_torque="60"/><joint node="rear_left_wheel_link" max_torque="60"/>
      <joint node="front_right_wheel_link" max_torque="60"/><joint node="rear_right_wheel_link" max_torque="60"/>
    </type><artifact name="h0" type="h" xyz="0 0 0.02"/></scene>)";
  Scene scene = loadSceneFromString(scene_text, "joints.xml", test::kArtifacts, test::testOptions());
  Environment& env = *scene.environment;
  std::vector<std::string> warnings;
  env.setLogSink([&](LogLevel level, std::string_view text) {
    if (level == LogLevel::Warning) warnings.emplace_back(text);
  });
  auto bridge = std::make_unique<TestBridge>(true);
  TestBridge& b = *bridge;
  env.addExtension("bridge", std::move(bridge), bridgeParams());
  env.step(10);
  REQUIRE(b.transport != nullptr);
  const RobotTopics& topics = b.transport->robots()[0];
  CHECK(topics.joints == std::vector<std::string>{"front_left_wheel_link", "front_right_wheel_link",
                                                  "rear_left_wheel_link", "rear_right_wheel_link"});
  CHECK(topics.joint_commands);
  CHECK(topics.parts == topics.joints);
  // its root is base_footprint, above a link named base_link: the root keeps its own name, and
  // base_link and the IMU's link are fixed frames on /tf_static, where the file puts them
  CHECK(topics.root_frame == "base_footprint");
  int fixed = 0;
  for (const StaticFrame& f : topics.statics) {
    if (f.child == "h0/base_link" && f.parent == "h0/base_footprint" && std::abs(f.pose[2] - 0.14493) < 1e-9) ++fixed;
    if (f.child == "h0/imu_link" && f.parent == "h0/base_footprint" && std::abs(f.pose[0] - 0.19) < 1e-9) ++fixed;
  }
  CHECK(fixed == 2);
  const Artifact& robot = *env.findArtifact("h0");
  const char* names[] = {"front_left_wheel_link", "rear_left_wheel_link", "front_right_wheel_link", "rear_right_wheel_link"};
  const double speeds[] = {2.0, 2.0, 2.0, 2.0};
  b.transport->receivedJointCommand(0, names, 4, nullptr, 0, speeds, 4);
  env.step(500);
  CHECK(robot.node("front_left_wheel_link")->jointVelocity() == Approx(2.0).margin(0.05));
  CHECK(robot.node("rear_right_wheel_link")->jointVelocity() == Approx(2.0).margin(0.05));
  CHECK(robot.root().pose().position.x() > 0.1);  // it drives ahead
  CHECK(warnings.empty());
  // a joint it lacks: the whole command dropped, the wheels keep what they had
  const char* wrong[] = {"front_left_wheel_link", "no_such_wheel"};
  const double stop[] = {0.0, 0.0, 0.0, 0.0};
  b.transport->receivedJointCommand(0, wrong, 2, nullptr, 0, stop, 2);
  env.step(100);
  CHECK(robot.node("front_left_wheel_link")->jointVelocity() == Approx(2.0).margin(0.05));
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Contains("/h0/joint_command was dropped (no joint 'no_such_wheel'"));
  // positions and names of other lengths: dropped too
  b.transport->receivedJointCommand(0, names, 4, stop, 1, nullptr, 0);
  env.step(1);
  CHECK(robot.node("front_left_wheel_link")->jointVelocity() == Approx(2.0).margin(0.05));
  // stopped by a good one
  b.transport->receivedJointCommand(0, names, 4, nullptr, 0, stop, 4);
  env.step(500);
  CHECK(std::abs(robot.node("front_left_wheel_link")->jointVelocity()) < 0.05);
  env.stop();  // (its summary logged while `warnings` is there)
}
