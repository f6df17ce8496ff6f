// A recording read back: from one of its saved states, the recorded scene steps again to the same
// poses, bit for bit; a file that is not a recording says so.
#include "record/mcap_reader.hpp"
#include "record/mcap_writer.hpp"

#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <filesystem>

using namespace ssx;
using namespace ssx::test;
namespace fs = std::filesystem;

namespace {

// a recording into `file` with a saved state every second
RecordOptions everySecond(const fs::path& file, const Scene& scene) {
  RecordOptions o;
  o.file = file;
  o.state_every_s = 1;
  o.scene_xml = scene.model->toXml();
  return o;
}

}  // namespace

TEST_CASE("recording: the recorded scene, restored from a saved state, steps to the recorded poses bit for bit",
          "[record][recording]") {
  const fs::path file = fs::current_path() / "recording_resim.mcap";
  const std::string xml = R"(<scene><environment timestep="0.002" seed="9" threads="2"/><type name="q" file="mk_quad.xml"/>
    <type name="box" file="box.xml"/><ground/>
    <swarm type="q" count="6" name="q{i}" spacing="1.2" xyz="0 0 0.05"><driver offset="0 0 1.5"/></swarm>
    <swarm type="box" count="3" name="b{i}" layout="random" min="-1 -1 2" max="1 1 3"/></scene>)";
  {
    Scene scene = loadSceneFromString(xml, "resim.xml", kArtifacts, testOptions());
    Recorder recorder(*scene.environment, everySecond(file, scene));
    scene.environment->step(1500);  // 3 s: take-off, boxes falling and landing
    recorder.finish();
  }
  const Recording r(file);
  Nanoseconds at = 0;
  const std::vector<std::byte> state = r.stateAtOrBefore(1'500'000'000, &at);
  CHECK(at == 1'040'000'000);
  // the scene as the recording keeps it, built again, on one thread this time
  SceneOptions options = testOptions();
  options.threads = 1;
  Scene again = buildScene(parseSceneString(r.sceneXml(), "recorded.xml", kArtifacts, options), options);
  Environment& env = *again.environment;
  env.restoreState(state);
  REQUIRE(env.time() == at);
  std::size_t compared = 0;
  for (std::size_t k = 0; k < r.times().size(); ++k) {
    if (r.times()[k] <= at) continue;
    while (env.time() < r.times()[k]) env.step();
    std::vector<float> now;
    for (const std::string& name : r.names())
      for (Eigen::Index c = 0; c < 3; ++c) now.push_back(static_cast<float>(env.findArtifact(name)->pose().position[c]));
    const std::vector<float> recorded = r.positions(k);
    REQUIRE(now.size() == recorded.size());
    INFO("sample " << k << " at " << toSeconds(r.times()[k]) << " s");
    CHECK(std::memcmp(now.data(), recorded.data(), now.size() * sizeof(float)) == 0);
    ++compared;
  }
  CHECK(compared == 49);  // 1.08 s to 3.0 s
  CHECK_THROWS_WITH(r.stateAtOrBefore(0), Catch::Contains("no saved state at or before 0"));
}

TEST_CASE("recording: an MCAP file that is not an ssx recording is refused, naming the file", "[record][recording]") {
  const fs::path file = fs::current_path() / "foreign.mcap";
  {
    detail::McapWriter w(file, "ros2", "someone else");
    w.close();
  }
  CHECK_THROWS_WITH(Recording(file), Catch::Contains("foreign.mcap: not an ssx recording: its profile is 'ros2'"));
  CHECK_THROWS_WITH(Recording(fs::current_path() / "missing.mcap"), Catch::Contains("cannot open the recording"));
}

TEST_CASE("recording: the message of a channel at or before a time is the one messages() has there",
          "[record][recording]") {
  const fs::path file = fs::current_path() / "recording_at_or_before.mcap";
  const std::string xml = R"(<scene><environment timestep="0.002" seed="4"/><type name="q" file="mk_quad.xml"/><ground/>
    <swarm type="q" count="2" name="q{i}" spacing="1.2" xyz="0 0 0.05"><driver offset="0 0 1"/></swarm></scene>)";
  {
    Scene scene = loadSceneFromString(xml, "at.xml", kArtifacts, testOptions());
    RecordOptions o;
    o.file = file;
    o.sensors = true;
    o.commands = true;
    o.scene_xml = scene.model->toXml();
    Recorder recorder(*scene.environment, o);
    scene.environment->step(250);  // 0.5 s: 13 samples at 25 Hz
    recorder.finish();
  }
  const Recording r(file);
  const auto all = r.messages("/ssx/sensors");
  REQUIRE(all.size() >= 10);
  for (std::size_t k = 0; k < all.size(); ++k) {
    INFO("message " << k << " at " << all[k].first << " ns");
    // at its own time, and just before the next one's
    const auto at = r.messageAtOrBefore("/ssx/sensors", all[k].first);
    REQUIRE(at);
    CHECK(at->first == all[k].first);
    CHECK(at->second == all[k].second);
    const Nanoseconds before_next = k + 1 < all.size() ? all[k + 1].first - 1 : all[k].first + 1'000'000'000;
    const auto late = r.messageAtOrBefore("/ssx/sensors", before_next);
    REQUIRE(late);
    CHECK(late->second == all[k].second);
  }
  CHECK_FALSE(r.messageAtOrBefore("/ssx/sensors", all.front().first - 1));
  CHECK_FALSE(r.messageAtOrBefore("/no/such/channel", all.back().first));
  const auto commands = r.messageAtOrBefore("/ssx/commands", all.back().first);
  REQUIRE(commands);
  CHECK(commands->second.find("\"q1\"") != std::string::npos);
}

TEST_CASE("recording: saved states are compressed and read back as saved and old uncompressed and corrupted ones too",
          "[record][recording]") {
  const fs::path file = fs::current_path() / "recording_states.mcap";
  const std::string xml = R"(<scene><environment timestep="0.002" seed="4"/><type name="q" file="mk_quad.xml"/>
    <ground/><swarm type="q" count="3" name="q{i}" spacing="1.2" xyz="0 0 0.05"><driver offset="0 0 1"/></swarm></scene>)";
  std::vector<std::byte> at_first;
  {
    Scene scene = loadSceneFromString(xml, "states.xml", kArtifacts, testOptions());
    Recorder recorder(*scene.environment, everySecond(file, scene));
    scene.environment->step(20);  // the first sample (25 Hz): a state
    at_first = scene.environment->saveState();
    scene.environment->step(100);
    recorder.finish();
  }
  detail::McapFile f = detail::readMcap(file);
  const auto state = std::find_if(f.attachments.begin(), f.attachments.end(),
                                  [](const auto& a) { return a.name == "state/40000000"; });
  REQUIRE(state != f.attachments.end());
  CHECK(state->media_type == "application/x-ssx-state+zstd");
  CHECK(state->data.size() < at_first.size() / 2);
  CHECK(Recording(file).stateAtOrBefore(40'000'000) == at_first);

  // as a recording made before states were compressed holds it
  state->media_type = "application/x-ssx-state";
  state->data = at_first;
  const fs::path old = fs::current_path() / "recording_states_old.mcap";
  detail::rewriteMcap(f, old);
  CHECK(Recording(old).stateAtOrBefore(40'000'000) == at_first);

  // compressed bytes that do not decompress: refused when asked for; a frame claiming more than
  // 1,024 times its size: refused when read
  std::vector<std::byte> broken;
  {
    const detail::McapFile g = detail::readMcap(file);
    const auto s = std::find_if(g.attachments.begin(), g.attachments.end(),
                                [](const auto& a) { return a.name == "state/40000000"; });
    broken.assign(s->data.begin(), s->data.end());
  }
  for (std::size_t i = broken.size() / 2; i < broken.size() / 2 + 64; ++i) broken[i] ^= std::byte{0x5A};
  state->media_type = "application/x-ssx-state+zstd";
  state->data = broken;
  const fs::path corrupted = fs::current_path() / "recording_states_corrupted.mcap";
  detail::rewriteMcap(f, corrupted);
  const Recording r(corrupted);
  CHECK_THROWS_WITH(r.stateAtOrBefore(40'000'000),
                    Catch::Contains("the saved state at 0.04") && Catch::Contains("does not decompress (corrupted)"));
  // a zstd frame header (magic, one segment with an 8-byte content size) saying 1 GiB in 13 bytes
  std::vector<std::byte> tiny = {std::byte{0x28}, std::byte{0xB5}, std::byte{0x2F}, std::byte{0xFD}, std::byte{0xE0}};
  for (int k = 0; k < 8; ++k) tiny.push_back(std::byte{static_cast<unsigned char>(k == 3 ? 0x40 : 0)});
  state->data = tiny;
  detail::rewriteMcap(f, corrupted);
  CHECK_THROWS_WITH(Recording(corrupted), Catch::Contains("its saved state 'state/40000000' is not a zstd frame of a "
                                                          "size it can hold (corrupted)"));
}
