// The JSON channels a run offers, recorded and live: the scene, a step's timing, the sensors, the commands.
#include <ssx/ssx.hpp>

#include "record/run_channels.hpp"
#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace ssx;
using namespace ssx::test;

namespace {

const char* kQuads = R"(<scene><environment timestep="0.002" seed="5" threads="1"/><type name="q" file="mk_quad.xml"/>
  <ground/><swarm type="q" count="2" name="q{i}" spacing="1.5" xyz="0 0 0.05"><driver offset="0 0 1"/></swarm></scene>)";

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("run channels: the scene in each robot's frame, its sensors and its command, as JSON", "[record][foxglove]") {
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  env.step(10);
  const std::vector<RecordedBody> bodies = recordedBodies(env);
  REQUIRE(bodies.size() == 2);

  const std::string update = detail::runSceneUpdate(env, bodies);
  CHECK(count(update, R"("frame_id":"q0")") == 1);
  CHECK(count(update, R"("frame_id":"q1")") == 1);
  CHECK(count(update, R"("frame_locked":true)") >= 2);

  // every robot's sensors by index, each measurement with its kind and stamp
  const std::string sensors = detail::sensorsJson(env);
  CHECK(sensors.front() == '{');
  CHECK(sensors.back() == '}');
  CHECK(count(sensors, R"("q0":{)") == 1);
  CHECK(count(sensors, R"("q1":{)") == 1);
  CHECK(count(sensors, R"("kind":)") >= 2);

  // every commandable robot's command: the set-point 1 m up, at the position level
  const std::string commands = detail::commandsJson(env);
  CHECK(count(commands, R"("q0":{"level":"position")") == 1);
  CHECK(count(commands, R"("q1":{"level":"position")") == 1);

  // a step's cost, ms, with its step and the contacts
  StepTiming t;
  t.step = 41;
  t.total = 2'500'000;
  t.lateness = 0;
  const std::string timing = detail::timingJson(t, 3);
  CHECK(timing.rfind(R"({"step":41,"contacts":3,"total_ms":2.5,)", 0) == 0);
  CHECK(count(timing, R"("late_ms":0})") == 1);
}

TEST_CASE("run channels: a sample taken again after steps holds the new measurements and commands",
          "[record][foxglove]") {
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  env.step(10);
  // one sample taken over and over, as the recorder and the Foxglove server keep theirs: what it
  // writes is what a fresh one writes at that step (the sensors and drivers it found the first time)
  detail::RunSample sample;
  sample.takeSensors(env);
  sample.takeCommands(env);
  const std::string first = sample.sensorsJson(env);
  CHECK(first == detail::sensorsJson(env));
  for (const double z : {2.0, 3.5}) {
    env.step(25);
    for (std::size_t i = 0; i < env.artifactCount(); ++i)
      if (auto* c = dynamic_cast<CommandInterface*>(env.artifact(i).driver())) {
        Setpoint p;
        p.position = Vec3(0, 0, z);
        c->setCommand(Command::position(p));
      }
    sample.takeSensors(env);
    sample.takeCommands(env);
    const std::string sensors = sample.sensorsJson(env);
    CHECK(sensors != first);  // (the stamps moved on)
    CHECK(sensors == detail::sensorsJson(env));
    CHECK(sample.commandsJson(env) == detail::commandsJson(env));
    CHECK(count(sample.commandsJson(env), z == 2.0 ? R"("values":[0,0,2,)" : R"("values":[0,0,3.5,)") == 2);
  }
}

TEST_CASE("run channels: the contacts of a step, taken and written later", "[record][foxglove]") {
  Scene scene = loadSceneFromString(R"(<scene><environment timestep="0.002" seed="1" threads="1"/><type name="b" file="box.xml"/>
    <ground/><artifact name="crate" type="b" xyz="0 0 0.3"/></scene>)",
                                    "crate.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  env.recordContacts(true);
  env.step(1000);  // 2 s: it fell and rests on the ground
  detail::RunSample sample;
  sample.takeContacts(env);
  const std::vector<EngineContact> resting = env.contacts();
  REQUIRE(resting.size() == 1);
  env.step(1);
  // written after a further step: what was taken, not what the world has now
  const std::string json = sample.contactsJson(env);
  CHECK(json.rfind(R"({"contacts":[{"a":"crate","b":"ground","position":[)", 0) == 0);
  CHECK(count(json, R"("normal":[0,0,1])") == 1);
  // the impulse over the step holds the crate up: its weight times the step
  const auto at = json.find(R"("impulse":)");
  REQUIRE(at != std::string::npos);
  CHECK(std::stod(json.substr(at + 10)) == Approx(resting[0].impulse));
  CHECK(resting[0].impulse > 0);
}
