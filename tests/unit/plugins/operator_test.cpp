// The operator extension: a velocity command moves every steered robot as one, the dead-man rule
// stops them, a joystick's axes and dead-man button steer; the force points away from the nearest
// obstacle or robot, grows as it gets nearer and is saturated; what cannot be steered is refused.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <string>
#include <vector>

using namespace ssx;
using namespace ssx::test;
using Catch::Contains;

namespace {

// four mk_quads 1.5 m apart hovering 1 m up (q0 at the origin), steered by operator "op"; `extra`
// adds to the scene
Scene steered(const std::string& op_attributes = "", const std::string& extra = "", const std::string& gravity = "",
              const std::string& robots = "q0 q1 q2 q3") {
  const std::string xml = R"(<scene><environment timestep="0.002" seed="5" threads="1"/>)" + gravity + R"(
    <type name="quad" file=")" + (kArtifacts / "mk_quad.xml").string() + R"("/>
    <type name="box" file=")" + (kArtifacts / "box.xml").string() + R"("/>
    <ground/>)" + extra + R"(
    <swarm type="quad" count="4" name="q{i}" spacing="1.5" xyz="0 0 1"/>
    <extension name="op" plugin="operator" robots=")" + robots + R"(" )" + op_attributes + R"(/>
  </scene>)";
  return loadSceneFromString(xml, "operator.xml", kArtifacts, testOptions());
}

OperatorInterface& op(Environment& env) {
  auto* o = dynamic_cast<OperatorInterface*>(env.extension("op"));
  REQUIRE(o != nullptr);
  return *o;
}

std::vector<Vec3> positions(const Environment& env) {
  std::vector<Vec3> out;
  for (int i = 0; i < 4; ++i) out.push_back(env.findArtifact("q" + std::to_string(i))->pose().position);
  return out;
}

}  // namespace

TEST_CASE("operator: a velocity command moves every steered robot as one, the dead-man rule stops them",
          "[operator]") {
  Scene scene = steered(R"(max_speed="0.6" deadman_s="0.5")");
  Environment& env = *scene.environment;
  std::vector<std::string> log;
  env.setLogSink([&](LogLevel, std::string_view m) { log.emplace_back(m); });
  env.step(1500);  // 3 s: hovering where they started
  const auto start = positions(env);
  CHECK(op(env).steered().size() == 4);
  for (int k = 0; k < 20; ++k) {  // 0.5 m/s east for 2 s, a command every 0.1 s
    op(env).command(Vec3(0.5, 0, 0), 0);
    env.step(50);
  }
  const auto moved = positions(env);
  for (int i = 0; i < 4; ++i) {
    INFO("q" << i);
    CHECK(moved[static_cast<std::size_t>(i)].x() - start[static_cast<std::size_t>(i)].x() == Approx(1.0).margin(0.2));
    CHECK(std::abs(moved[static_cast<std::size_t>(i)].y() - start[static_cast<std::size_t>(i)].y()) < 0.05);
  }
  // no command since: after 0.5 s they are told to stop, and hold where they stopped
  env.step(1000);
  const auto stopped = positions(env);
  env.step(500);
  for (int i = 0; i < 4; ++i) {
    INFO("q" << i);
    CHECK((positions(env)[static_cast<std::size_t>(i)] - stopped[static_cast<std::size_t>(i)]).norm() < 0.05);
    CHECK(env.findArtifact("q" + std::to_string(i))->state().linear_velocity.norm() < 0.05);
    // (the overshoot of TeleKyb's velocity level: they stop within 0.5 m of where the dead-man caught them)
    CHECK(stopped[static_cast<std::size_t>(i)].x() - start[static_cast<std::size_t>(i)].x() < 1.7);
  }
  // too fast: clipped to max_speed
  for (int k = 0; k < 30; ++k) {
    op(env).command(Vec3(5, 0, 0), 0);
    env.step(50);
  }
  CHECK(env.findArtifact("q0")->state().linear_velocity.norm() == Approx(0.6).margin(0.1));
  CHECK_THROWS_WITH(op(env).command(Vec3(NAN, 0, 0), 0), Contains("not finite"));
  env.stop();
  CHECK_THAT(log.back(), Contains("operator: 50 commands, 1 stops by the dead-man rule"));
}

TEST_CASE("operator: a joystick steers while its dead-man button is held", "[operator]") {
  Scene scene = steered(R"(max_speed="0.5" joy_axes="1 0 -1 3" joy_deadman_button="4")");
  Environment& env = *scene.environment;
  env.step(1500);
  const double x0 = env.findArtifact("q0")->pose().position.x();
  const std::vector<float> forward{0.0f, 1.0f, 0.0f, 0.0f};
  std::vector<int> held{0, 0, 0, 0, 1};
  for (int k = 0; k < 20; ++k) {
    op(env).joy(forward, held);
    env.step(50);
  }
  CHECK(env.findArtifact("q0")->pose().position.x() - x0 == Approx(1.0).margin(0.2));
  // released: stopped at once (before the dead-man time)
  const std::vector<int> released{0, 0, 0, 0, 0};
  op(env).joy(forward, released);
  env.step(1000);
  CHECK(env.findArtifact("q0")->state().linear_velocity.norm() < 0.05);
}

TEST_CASE("operator: the force points away from what is near, grows as it nears, and saturates", "[operator]") {
  // q0 steered, at the origin (1 m up); a pillar east of it; the other quadrotors 1.5 m and more
  // away (the force's range: they add nothing)
  auto force = [](double gap, const std::string& attributes = "", const std::string& more = "") {
    const std::string pillar = R"(<obstacle name="pillar" xyz=")" + std::to_string(gap + 0.2) +
                               R"( 0 1"><cylinder radius="0.2" length="2"/></obstacle>)";
    Scene s = steered(attributes, pillar + more, R"(<physics gravity="0 0 0"/>)", "q0");
    s.environment->start();
    return op(*s.environment).force();
  };
  const Vec3 far = force(1.6), mid = force(1.0), near = force(0.4);
  CHECK(far.norm() == 0);  // beyond force_range (1.5 m)
  CHECK(mid.x() < 0);
  CHECK(mid.normalized().isApprox(-Vec3::UnitX(), 1e-9));
  CHECK(mid.norm() == Approx(2 * (1 - 1.0 / 1.5)));  // force_gain (1 - d / R)
  CHECK(near.norm() == Approx(2 * (1 - 0.4 / 1.5)));
  CHECK(near.norm() > mid.norm());
  // a robot that is not steered pushes too: a box 1 m north of q0
  const Vec3 both = force(1.0, "", R"(<artifact name="other" type="box" xyz="0 -1 1"/>)");
  CHECK(both.y() == Approx(2 * (1 - 1.0 / 1.5)));
  CHECK(both.x() == Approx(mid.x()));
  // saturated
  CHECK(force(0.1, R"(force_gain="100" force_max="3")").norm() == Approx(3));
}

TEST_CASE("operator: what cannot be steered, and a malformed joystick map, are refused before anything runs",
          "[operator]") {
  auto load = [](const std::string& op) {
    return loadSceneFromString(R"(<scene><type name="box" file=")" + (kArtifacts / "box.xml").string() +
                                   R"("/><type name="quad" file=")" + (kArtifacts / "mk_quad.xml").string() + R"("/>
      <artifact name="b" type="box"/><artifact name="q" type="quad" xyz="2 0 1"/>
      )" + op + "</scene>",
                               "bad.xml", kArtifacts, testOptions());
  };
  CHECK_THROWS_WITH(load(R"(<extension name="op" plugin="operator" robots="b"/>)"),
                    Contains("bad.xml:3: error:") && Contains("'b' cannot be steered: its driver takes no velocity commands"));
  CHECK_THROWS_WITH(load(R"(<extension name="op" plugin="operator" robots="q" joy_axes="1 0"/>)"),
                    Contains("joy_axes must be four axis numbers"));
  CHECK_THROWS_WITH(load(R"(<extension name="op" plugin="operator"/>)"), Contains("robots"));
}
