// A robot selected in a replay: its velocities from the recorded poses, its command and its sensors
// as the recording has them at the sample shown; none of either from a recording without them.
#include "../../../../plugins/viewer/replay_details.hpp"

#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>

using namespace ssx;
using namespace ssx::test;
namespace fs = std::filesystem;

namespace {
const char* const kScene = R"(<scene><environment timestep="0.002" seed="6"/><type name="q" file="mk_quad.xml"/>
  <type name="box" file="box.xml"/><ground/>
  <swarm type="q" count="2" name="q{i}" spacing="1.5" xyz="0 0 0.05"><driver offset="0 0 1"/></swarm>
  <artifact name="crate" type="box" xyz="3 0 1"/></scene>)";

fs::path record(const char* name, bool channels) {
  const fs::path file = fs::current_path() / name;
  Scene scene = loadSceneFromString(kScene, "details.xml", kArtifacts, testOptions());
  RecordOptions o;
  o.file = file;
  o.sensors = o.commands = channels;
  o.scene_xml = scene.model->toXml();
  Recorder recorder(*scene.environment, o);
  scene.environment->step(500);  // 1 s: taking off, the crate falling
  recorder.finish();
  return file;
}

// the member `artifact` of the recorded channel's message at time t
nlohmann::json recorded(const Recording& r, const char* topic, Nanoseconds t, const char* artifact) {
  return nlohmann::json::parse(r.messageAtOrBefore(topic, t)->second).at(artifact);
}
}  // namespace

TEST_CASE("replay details: velocities from the recorded poses, the command and sensors as recorded",
          "[viewer][replay]") {
  const Recording r(record("replay_details.mcap", true));
  viewer::ReplayDetails details(r);
  REQUIRE(details.hasCommands());
  REQUIRE(details.hasSensors());
  const std::size_t q1 = static_cast<std::size_t>(
      std::find(r.names().begin(), r.names().end(), "q1") - r.names().begin());
  const std::size_t crate = static_cast<std::size_t>(
      std::find(r.names().begin(), r.names().end(), "crate") - r.names().begin());
  REQUIRE(q1 < r.names().size());
  REQUIRE(crate < r.names().size());
  for (const std::size_t k : {std::size_t{0}, std::size_t{7}, r.times().size() - 1}) {
    INFO("sample " << k);
    const nlohmann::json d = nlohmann::json::parse(details.json(k, q1, "q1"));
    CHECK(d.at("body") == q1);
    CHECK(d.at("name") == "q1");
    // the velocity over the interval that ends at the sample (begins, at the first)
    const std::size_t a = k == 0 ? 0 : k - 1, b = k == 0 ? 1 : k;
    const double dt = toSeconds(r.times()[b] - r.times()[a]);
    const std::vector<float> pa = r.positions(a), pb = r.positions(b);
    for (std::size_t i = 0; i < 3; ++i)
      CHECK(d.at("v")[i].get<double>() == Approx((double(pb[3 * q1 + i]) - pa[3 * q1 + i]) / dt).margin(1e-9));
    // the turn between the two samples, as an angle and axis
    const std::vector<float> qa = r.orientations(a), qb = r.orientations(b);
    const Quat from(qa[4 * q1], qa[4 * q1 + 1], qa[4 * q1 + 2], qa[4 * q1 + 3]);
    const Quat to(qb[4 * q1], qb[4 * q1 + 1], qb[4 * q1 + 2], qb[4 * q1 + 3]);
    const Eigen::AngleAxisd turn(to.normalized() * from.normalized().conjugate());
    const Vec3 w = turn.axis() * (turn.angle() > M_PI ? turn.angle() - 2 * M_PI : turn.angle()) / dt;
    for (Eigen::Index i = 0; i < 3; ++i) CHECK(d.at("w")[static_cast<std::size_t>(i)].get<double>() == Approx(w[i]).margin(1e-6));
    // the command and the sensors recorded at the sample's time
    const Nanoseconds t = r.times()[k];
    CHECK(d.at("command") == recorded(r, "/ssx/commands", t, "q1"));
    const nlohmann::json sensors = recorded(r, "/ssx/sensors", t, "q1");
    REQUIRE(d.at("sensors").size() == sensors.size());
    std::size_t imus = 0;
    for (const auto& m : d.at("sensors")) {
      CHECK(m.at("sensor") == m.at("kind"));
      imus += m.at("kind") == "imu";
    }
    CHECK(imus == 1);
    CHECK(d.at("sensors")[0].at("stamp") == sensors.at("0").at("stamp"));
  }
  // the second robot's details at the same sample are its own
  const nlohmann::json q0 = nlohmann::json::parse(details.json(10, 0, "q0"));
  CHECK(q0.at("command") == recorded(r, "/ssx/commands", r.times()[10], "q0"));
  // a crate has no driver and no sensor: no command, no sensors; it falls
  const nlohmann::json c = nlohmann::json::parse(details.json(10, crate, "crate"));
  CHECK(c.at("command").is_null());
  CHECK(c.at("sensors").empty());
  CHECK(c.at("v")[2].get<double>() < -0.5);
}

TEST_CASE("replay details: a recording of poses alone gives velocities and nothing else", "[viewer][replay]") {
  const Recording r(record("replay_details_poses.mcap", false));
  viewer::ReplayDetails details(r);
  CHECK_FALSE(details.hasCommands());
  CHECK_FALSE(details.hasSensors());
  const nlohmann::json d = nlohmann::json::parse(details.json(5, 0, "q0"));
  CHECK(d.at("command").is_null());
  CHECK(d.at("sensors").empty());
  CHECK(d.at("v").size() == 3);
}
