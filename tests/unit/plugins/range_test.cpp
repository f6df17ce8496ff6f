// The range sensor in a scene: robots from the environment's neighbour index, obstacles at their
// nearest surface point, field of view, count limit, frames.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>

using namespace ssx;

namespace {

Scene rangeScene(const std::string& sensor_attributes, std::uint64_t seed = 1) {
  const std::string xml = R"(<scene><environment timestep="0.01" seed=")" + std::to_string(seed) + R"("/>
    <physics gravity="0 0 0"/>
    <type name="dot" file="dot.xml"/>
    <obstacle name="pillar" xyz="0 3 0"><cylinder radius="0.5" length="4"/></obstacle>
    <artifact name="me" type="dot" rpy="0 0 1.5707963267948966"><sensor index="0" )" +
                          sensor_attributes + R"(/></artifact>
    <artifact name="east" type="dot" xyz="2 0 0"/>
    <artifact name="west" type="dot" xyz="-1 0 0"/>
    <artifact name="north" type="dot" xyz="0 1.5 0"/>
    <artifact name="far" type="dot" xyz="10 0 0"/>
  </scene>)";
  return loadSceneFromString(xml, "range.xml", std::filesystem::path(SSX_TEST_DATA_DIR) / "valid");
}

const RangeMeasurement& seen(Environment& env) {
  return dynamic_cast<const RangeMeasurement&>(env.findArtifact("me")->sensor(0).latest());
}

std::vector<std::string> names(Environment& env) {
  std::vector<std::string> out;
  for (const auto& d : seen(env).detections) out.push_back(env.artifact(d.artifact).name() + (d.obstacle ? "*" : ""));
  return out;
}

}  // namespace

TEST_CASE("the range sensor sees robots and obstacles within range, nearest first", "[range]") {
  Scene s = rangeScene(R"(range="2.6")");
  Environment& env = *s.environment;
  env.step();
  // west 1 m, north 1.5 m, east 2 m, the pillar's surface 2.5 m away; far and itself are not seen
  CHECK(names(env) == std::vector<std::string>{"west", "north", "east", "pillar*"});
  const auto& d = seen(env).detections;
  CHECK(d[3].relative.isApprox(Vec3(0, 2.5, 0)));
  CHECK(d[3].distance == Approx(2.5));
  CHECK(d[0].relative.isApprox(Vec3(-1, 0, 0)));
}

TEST_CASE("field of view, count limit and body frame", "[range]") {
  // "me" faces +y (yaw 90 deg): a 90 degree cone sees north and the pillar only
  Scene cone = rangeScene(R"(range="2.6" fov_deg="90" frame="body")");
  cone.environment->step();
  CHECK(names(*cone.environment) == std::vector<std::string>{"north", "pillar*"});
  // in the body frame, straight ahead is +x
  CHECK(seen(*cone.environment).detections[0].relative.isApprox(Vec3(1.5, 0, 0), 1e-9));

  Scene nearest = rangeScene(R"(range="5" max_count="2" obstacles="false")");
  nearest.environment->step();
  CHECK(names(*nearest.environment) == std::vector<std::string>{"west", "north"});
}

TEST_CASE("range noise repeats with the seed", "[range]") {
  auto first = [](std::uint64_t seed) {
    Scene s = rangeScene(R"(range="3" position_noise="0.05")", seed);
    s.environment->step();
    return seen(*s.environment).detections[0].relative;
  };
  CHECK(first(3) == first(3));
  CHECK(first(3) != first(4));
  CHECK((first(3) - Vec3(-1, 0, 0)).norm() < 0.3);
}

TEST_CASE("range sensors in parallel: bitwise the same on 1, 2 and 4 threads, each from the current positions",
          "[range][threads]") {
  // the neighbour index is rebuilt by the first query after each snapshot, whichever thread makes
  // it; sensors at period 3 leave steps without queries in between. Every measurement must be the
  // one the current positions give, and the same bits on any number of threads
  constexpr double kRange = 1.5;
  auto run = [&](int threads) {
    const std::string xml = R"(<scene><environment timestep="0.01" seed="3" threads=")" + std::to_string(threads) +
                            R"("/><type name="dot" file="dot.xml"/>
      <swarm type="dot" count="400" name="d{i}" layout="random" min="-8 -8 0" max="8 8 4" min_distance="0.3">
        <sensor index="0" range="1.5" period="3"/></swarm></scene>)";
    Scene s = loadSceneFromString(xml, "parallel_range.xml", std::filesystem::path(SSX_TEST_DATA_DIR) / "valid");
    Environment& env = *s.environment;
    std::vector<double> record;
    std::size_t checked = 0;
    for (int k = 0; k < 30; ++k) {
      env.step();  // falling: every position changes every step
      if (k % 3 != 0) continue;
      for (std::size_t i = 0; i < env.artifactCount(); ++i) {
        const Artifact& a = env.artifact(i);
        const auto& m = dynamic_cast<const RangeMeasurement&>(a.sensor(0).latest());
        std::vector<std::size_t> expected, got;
        for (std::size_t j = 0; j < env.artifactCount(); ++j)
          if (j != i && (env.artifact(j).pose().position - a.pose().position).norm() <= kRange) expected.push_back(j);
        for (const auto& d : m.detections) {
          got.push_back(d.artifact);
          record.insert(record.end(), {static_cast<double>(d.artifact), d.relative.x(), d.relative.y(), d.relative.z()});
        }
        std::sort(got.begin(), got.end());
        REQUIRE(got == expected);
        checked += got.size();
      }
    }
    CHECK(checked > 1000);  // the swarm is dense enough to see one another
    return record;
  };
  const std::vector<double> one = run(1);
  CHECK(run(2) == one);
  CHECK(run(4) == one);
}
