// The recorder: every body's pose at the rate asked for and saved states at their interval, written
// off the stepping thread; nothing dropped when it may wait; a write that fails stops the run.
#include <ssx/ssx.hpp>

#include "record/foxglove.hpp"
#include "record/mcap_reader.hpp"
#include "record/mcap_writer.hpp"
#include "scene_util.hpp"
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <map>

using namespace ssx;
using namespace ssx::test;
namespace fs = std::filesystem;

namespace {

const char* kQuads = R"(<scene><environment timestep="0.002" seed="5" threads="2"/><type name="q" file="mk_quad.xml"/>
  <ground/><swarm type="q" count="4" name="q{i}" spacing="1.5" xyz="0 0 0.05"><driver offset="0 0 1"/></swarm></scene>)";

RecordOptions options(const fs::path& file, const Scene& scene) {
  RecordOptions o;
  o.file = file;
  o.rate_hz = 25;
  o.state_every_s = 1;
  o.scene_xml = scene.model->toXml();
  o.scene_label = "quads.xml";
  return o;
}

}  // namespace

TEST_CASE("recorder: poses of every body at 25 Hz, saved states every second, the scene and its seed",
          "[record][recorder]") {
  const fs::path file = fs::current_path() / "recorder_quads.mcap";
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  Recorder recorder(env, options(file, scene));
  env.step(1000);  // 2 s
  const RecordSummary s = recorder.finish();
  CHECK(s.samples == 50);
  CHECK(s.dropped == 0);
  CHECK(s.states == 2);  // at the first sample, 0.04 s, and at 1.04 s
  CHECK(s.bodies == 4);
  CHECK(s.bytes == fs::file_size(file));
  CHECK(s.str(file).find("50 samples of 4 bodies (0 dropped), 2 saved states") != std::string::npos);

  const Recording r(file);
  CHECK(r.complete());
  CHECK(r.names() == std::vector<std::string>{"q0", "q1", "q2", "q3"});
  REQUIRE(r.times().size() == 50);
  for (std::size_t k = 0; k < 50; ++k) CHECK(r.times()[k] == static_cast<Nanoseconds>(k + 1) * 40'000'000);
  // the last sample is the world as it is now, to the float
  const std::vector<float> last = r.positions(49);
  for (std::size_t i = 0; i < 4; ++i)
    for (Eigen::Index k = 0; k < 3; ++k)
      CHECK(last[3 * i + static_cast<std::size_t>(k)] == static_cast<float>(env.findArtifact(r.names()[i])->pose().position[k]));
  CHECK(last[2] > 0.5f);  // they took off
  CHECK(r.stateTimes() == std::vector<Nanoseconds>{40'000'000, 1'040'000'000});
  CHECK(r.sceneXml() == scene.model->toXml());
  CHECK(r.sceneLabel() == "quads.xml");
  CHECK(r.seed() == 5);
  CHECK(r.version() == SSX_VERSION_STRING);
  // the compact poses, and (four bodies: Foxglove's channels by default) a transform message per sample and the shapes once
  CHECK(r.channels() == std::vector<std::pair<std::string, std::uint64_t>>{{"/ssx/poses", 50}, {"/tf", 50}, {"/scene", 1}});
  // a second finish is the same summary; steps after it are not recorded
  CHECK(recorder.finish().samples == 50);
  env.step(100);
  CHECK(Recording(file).times().size() == 50);
}

TEST_CASE("recorder: with a queue of one and no dropping, the stepper waits and every sample is written",
          "[record][recorder]") {
  const fs::path file = fs::current_path() / "recorder_wait.mcap";
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  RecordOptions o = options(file, scene);
  o.queue_samples = 1;
  o.rate_hz = 0;  // every step
  Recorder recorder(*scene.environment, o);
  scene.environment->step(500);
  const RecordSummary s = recorder.finish();
  CHECK(s.samples == 500);
  CHECK(s.dropped == 0);
  CHECK(Recording(file).times().size() == 500);
}

TEST_CASE("recorder: a recording that cannot be written stops the run with the file's name", "[record][recorder]") {
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  Recorder recorder(env, options("/dev/full", scene));  // takes the open, refuses every byte
  CHECK_THROWS_WITH(env.step(100), Catch::Contains("/dev/full"));
  CHECK(env.state() == Environment::State::Failed);
  CHECK_THROWS_WITH(recorder.finish(), Catch::Contains("/dev/full"));
  // bad options are refused before a file is made
  RecordOptions bad = options(fs::current_path() / "never.mcap", scene);
  bad.rate_hz = -1;
  CHECK_THROWS_WITH(Recorder(env, bad), Catch::Contains("rate_hz"));
  CHECK_FALSE(fs::exists(bad.file));
}

TEST_CASE("recorder: Foxglove's /tf and /scene, every step's timing and the sensors' measurements", "[record][recorder]") {
  const fs::path file = fs::current_path() / "recorder_channels.mcap";
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  RecordOptions o = options(file, scene);
  o.timing = true;
  o.sensors = true;  // foxglove unset: 4 bodies get it
  Recorder recorder(env, o);
  env.step(1000);
  const RecordSummary s = recorder.finish();
  const std::vector<std::string> topics{"/ssx/poses", "/tf", "/scene", "/ssx/timing", "/ssx/sensors"};
  CHECK(s.channels == topics);
  CHECK(s.str(file).find("; channels /ssx/poses, /tf, /scene, /ssx/timing, /ssx/sensors") != std::string::npos);

  const Recording r(file);
  CHECK(r.encoding("/tf") == "json");
  CHECK(r.encoding("/nothing").empty());
  CHECK_THROWS_WITH(r.messages("/nothing"), Catch::Contains("no channel '/nothing'") && Catch::Contains("/ssx/sensors"));
  // a transform per body at every pose sample, at its time, with the sample's position
  const auto tf = r.messages("/tf");
  REQUIRE(tf.size() == 50);
  for (std::size_t k = 0; k < tf.size(); ++k) CHECK(tf[k].first == r.times()[k]);
  const std::vector<float> last = r.positions(49);
  for (std::size_t i = 0; i < 4; ++i) {
    std::string x;
    detail::appendNumber(x, last[3 * i]);
    CHECK(tf.back().second.find(R"("child_frame_id":"q)" + std::to_string(i) + R"(","translation":{"x":)" + x + ",") !=
          std::string::npos);
  }
  // the shapes once: an entity per quadrotor, locked to its frame, and the ground in the world's
  const auto scene_update = r.messages("/scene");
  REQUIRE(scene_update.size() == 1);
  for (const char* id : {R"("id":"q0")", R"("id":"q3")", R"("id":"world")"})
    CHECK(scene_update[0].second.find(id) != std::string::npos);
  // every step's cost, in order, stamped with the step's end
  const auto timing = r.messages("/ssx/timing");
  REQUIRE(timing.size() == 1000);
  for (std::size_t k = 0; k < timing.size(); ++k) {
    CHECK(timing[k].second.rfind(R"({"step":)" + std::to_string(k) + ",", 0) == 0);
    CHECK(timing[k].first == static_cast<Nanoseconds>(k + 1) * env.timestep());
  }
  // each robot's IMU and pose sensors at every sample
  const auto sensors = r.messages("/ssx/sensors");
  REQUIRE(sensors.size() == 50);
  for (const char* what : {R"("q0":{)", R"("q3":{)", R"("kind":"imu")", R"("kind":"pose")", R"("gyroscope":[)"})
    CHECK(sensors.back().second.find(what) != std::string::npos);

  // asked off: the poses alone
  Scene again = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  RecordOptions plain = options(file, again);
  plain.foxglove = false;
  Recorder off(*again.environment, plain);
  again.environment->step(100);
  CHECK(off.finish().channels == std::vector<std::string>{"/ssx/poses"});
  CHECK(Recording(file).channels().size() == 1);
}

TEST_CASE("recorder: /ssx/timing counts each step's contact points: none in the air, some once a box lands",
          "[record][recorder]") {
  const fs::path file = fs::current_path() / "recorder_contacts.mcap";
  Environment env;
  env.addGround();
  Artifact& box = env.addArtifact("box", Pose{Vec3(0, 0, 0.3), Quat::Identity()});
  box.addPhysicRoot(boxBody(Vec3(0.2, 0.2, 0.2), 1.0));
  env.start();
  RecordOptions o;
  o.file = file;
  o.timing = true;
  Recorder recorder(env, o);
  env.step(1000);  // 1 s: it falls 0.2 m in about 0.2 s and rests
  recorder.finish();
  const auto timing = Recording(file).messages("/ssx/timing");
  REQUIRE(timing.size() == 1000);
  CHECK(timing[10].second.find(R"("contacts":0,)") != std::string::npos);
  CHECK(timing[999].second.find(R"("contacts":0,)") == std::string::npos);
  CHECK(timing[999].second.find(R"("contacts":)") != std::string::npos);
}

TEST_CASE("recorder: /ssx/commands says each quadrotor's command level and values at every sample", "[record][recorder]") {
  const fs::path file = fs::current_path() / "recorder_commands.mcap";
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  RecordOptions o = options(file, scene);
  o.foxglove = false;
  o.commands = true;
  Recorder recorder(env, o);
  env.step(20);  // the first sample, at 0.04 s: every one at its position set-point
  dynamic_cast<CommandInterface&>(*env.findArtifact("q1")->driver()).setCommand(Command::rotors({400, 410, 420, 430}));
  env.step(20);
  recorder.finish();
  const auto commands = Recording(file).messages("/ssx/commands");
  REQUIRE(commands.size() == 2);
  CHECK(commands[0].second.find(R"("q1":{"level":"position","values":[)") != std::string::npos);
  CHECK(commands[1].second.find(R"("q1":{"level":"rotors","values":[400,410,420,430]})") != std::string::npos);
  CHECK(commands[1].second.find(R"("q0":{"level":"position")") != std::string::npos);
}

TEST_CASE("recorder: a robot's joined parts (wheels on hinges) are bodies of their own, each with its shapes",
          "[record][recorder][joints]") {
  const fs::path file = fs::current_path() / "recorder_burger.mcap";
  const char* xml = R"(<scene><environment timestep="0.002" seed="1"/><type name="burger" file="turtlebot3_burger.xml"/>
    <ground/><artifact name="burger" type="burger" xyz="0 0 0"><driver controller="twist" twist="0.1 0.5 0"/></artifact>
    </scene>)";
  Scene scene = loadSceneFromString(xml, "burger.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  Recorder recorder(env, options(file, scene));
  env.step(500);  // 1 s
  CHECK(recorder.finish().bodies == 4);
  const Recording r(file);
  CHECK(r.names() == std::vector<std::string>{"burger", "burger/left_wheel", "burger/right_wheel", "burger/caster"});
  // each body's pose is its head node's, to the float: the wheels where they turned to
  const Artifact& burger = *env.findArtifact("burger");
  const std::vector<float> positions = r.positions(r.times().size() - 1);
  const std::vector<float> orientations = r.orientations(r.times().size() - 1);
  for (std::size_t i = 1; i < 3; ++i) {
    const Pose wheel = burger.node(r.names()[i].substr(7))->pose();
    for (Eigen::Index k = 0; k < 3; ++k) CHECK(positions[3 * i + static_cast<std::size_t>(k)] == static_cast<float>(wheel.position[k]));
    const Quat& q = wheel.orientation;
    const double dot = orientations[4 * i] * q.w() + orientations[4 * i + 1] * q.x() + orientations[4 * i + 2] * q.y() +
                       orientations[4 * i + 3] * q.z();
    CHECK(std::abs(dot) > 1 - 1e-6);
  }
  // the wheels' cylinders move with the wheels, the chassis' box with the chassis
  const auto update = r.messages("/scene");
  REQUIRE(update.size() == 1);
  for (const char* frame : {R"("frame_id":"burger")", R"("frame_id":"burger/left_wheel")", R"("frame_id":"burger/right_wheel")"})
    CHECK(update[0].second.find(frame) != std::string::npos);
}

TEST_CASE("recording: times that go back (a state restored while recording) are said at once and refused when read, "
          "at their byte",
          "[record][recorder]") {
  const fs::path file = fs::current_path() / "recorder_back.mcap";
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  std::vector<std::string> warnings;
  env.setLogSink([&](LogLevel level, std::string_view text) {
    if (level == LogLevel::Warning) warnings.emplace_back(text);
  });
  Recorder recorder(env, options(file, scene));
  env.step(100);
  const std::vector<std::byte> early = env.saveState();
  env.step(100);
  env.restoreState(early);  // a reset loop for learning does this
  env.step(100);
  recorder.finish();
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Contains("the time went back from 0.400000 s to 0.240000 s") &&
                              Catch::Contains("record each episode into a file of its own"));
  CHECK_THROWS_WITH(Recording(file), Catch::StartsWith(file.string() + ": byte ") &&
                                         Catch::Contains("a pose sample at 0.240000 s follows one at 0.400000 s") &&
                                         Catch::Contains("go back or repeat"));
}

TEST_CASE("recording: a pose sample of the wrong length is refused when read, with the file and its byte",
          "[record][recorder]") {
  const fs::path file = fs::current_path() / "recorder_length.mcap";
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  {
    Recorder recorder(*scene.environment, options(file, scene));
    scene.environment->step(100);
  }
  // the same file with the third pose sample one byte short, its count unchanged
  const ssx::detail::McapFile f = ssx::detail::readMcap(file);
  const fs::path bad = fs::current_path() / "recorder_length_bad.mcap";
  int poses = 0;
  ssx::detail::rewriteMcap(f, bad, [&](std::size_t i, std::span<const std::byte> data) {
    const bool third = f.channels.at(f.messages[i].channel).topic == "/ssx/poses" && ++poses == 3;
    return third ? data.first(data.size() - 1) : data;
  });
  CHECK(Recording(file).times().size() == 5);
  CHECK_THROWS_WITH(Recording(bad), Catch::StartsWith(bad.string() + ": byte ") &&
                                        Catch::Contains("a pose sample at 0.120000 s of 83 bytes, holding 4 bodies") &&
                                        Catch::Contains("which take 84 bytes (corrupted)"));
}

TEST_CASE("recorder: a second run recording into the file another is writing is refused, the first unharmed",
          "[record][recorder]") {
  const fs::path file = fs::current_path() / "recorder_twice.mcap";
  Scene first = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Scene second = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Recorder recorder(*first.environment, options(file, first));
  first.environment->step(50);
  CHECK_THROWS_WITH(Recorder(*second.environment, options(file, second)),
                    Catch::Contains("is being written by another run now") && Catch::Contains(file.string()));
  first.environment->step(50);
  recorder.finish();
  const Recording r(file);
  CHECK(r.complete());
  CHECK(r.times().size() == 5);
  // once it is closed, the file may be written again
  Recorder again(*second.environment, options(file, second));
  second.environment->step(50);
  CHECK(again.finish().samples == 2);
}

TEST_CASE("recorder: made on a running environment it sizes its state buffer first and records the world's states",
          "[record][recorder]") {
  const fs::path file = fs::current_path() / "recorder_prepared.mcap";
  Scene scene = loadSceneFromString(kQuads, "quads.xml", kArtifacts, testOptions());
  Environment& env = *scene.environment;
  env.step(10);
  const std::uint64_t before = env.stateHash();
  Recorder recorder(env, options(file, scene));  // (prepare(): a state saved and kept, not recorded)
  CHECK(env.stateHash() == before);              // nothing in the world moved
  recorder.prepare();                            // (again: nothing)
  std::vector<std::vector<std::byte>> expected;
  env.step(10);  // the first sample, at 0.04 s: a state
  expected.push_back(env.saveState());
  env.step(500);  // 1.04 s
  expected.push_back(env.saveState());
  env.step(500);  // 2.04 s
  expected.push_back(env.saveState());
  const RecordSummary s = recorder.finish();
  CHECK(s.states == 3);
  CHECK(s.state_ms_first > 0);
  CHECK(s.state_ms_max > 0);
  const Recording r(file);
  REQUIRE(r.stateTimes() == std::vector<Nanoseconds>{40'000'000, 1'040'000'000, 2'040'000'000});
  for (std::size_t k = 0; k < 3; ++k) CHECK(r.stateAtOrBefore(r.stateTimes()[k]) == expected[k]);
}
