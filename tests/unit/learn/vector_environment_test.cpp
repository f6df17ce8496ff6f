// Copies of one scene stepped together (ssx/vector_environment.hpp): a copy ends as it would
// alone, on 1 and 2 threads, whatever its index or its neighbours; copies left out of a step or a
// reset keep every bit; a reset with a seed draws the same noise again and another seed other
// noise; states and IMU readings come out in one array; commands go in checked whole; moving
// robots moves them; nonsense is refused with the copy and robot named.
#include "scene_util.hpp"
#include "test_util.hpp"

#include <ssx/ssx.hpp>
#include <ssx/vector_environment.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

using namespace ssx;
using Catch::Contains;
using ssx::test::kArtifacts;

namespace {

// `robots` Crazyflies taking off to 1 m; copy `seed` differs when seeds are given per copy
Scene crazyflies(std::size_t robots = 1, std::uint64_t seed = 4, const char* name = "cf{i}") {
  SceneOptions options;
  options.threads = 1;
  return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"" + std::to_string(seed) +
                                 "\"/><type name=\"cf\" file=\"" + (kArtifacts / "crazyflie.xml").string() +
                                 "\"/><ground/><swarm type=\"cf\" count=\"" + std::to_string(robots) + "\" name=\"" +
                                 name + "\" spacing=\"1\" xyz=\"0 0 0.05\"><driver offset=\"0 0 1\"/></swarm></scene>",
                             "cf.xml", kArtifacts, options);
}

std::vector<std::uint64_t> hashes(VectorEnvironment& v) {
  std::vector<std::uint64_t> out;
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(v[i].stateHash());
  return out;
}

}  // namespace

TEST_CASE("vector environment: a copy ends as it would alone, on 1 and 2 threads, whatever its index", "[learn]") {
  // copies with seeds 4, 5, 6: each one's end state is that of its scene stepped alone
  auto seeded = [](std::size_t i) { return crazyflies(2, 4 + i); };
  std::vector<std::uint64_t> alone;
  for (std::size_t i = 0; i < 3; ++i) {
    Scene s = seeded(i);
    s.environment->step(300);
    alone.push_back(s.environment->stateHash());
  }
  CHECK(alone[0] != alone[1]);
  for (const int threads : {1, 2}) {
    VectorEnvironment v(seeded, 3, threads);
    CHECK(v.threadCount() == static_cast<unsigned>(threads));
    v.step(100);
    v.step(200);
    CHECK(hashes(v) == alone);
  }
  // the copies in the other order: the same states, permuted
  VectorEnvironment reversed([&](std::size_t i) { return seeded(2 - i); }, 3, 2);
  reversed.step(300);
  CHECK(hashes(reversed) == std::vector<std::uint64_t>{alone[2], alone[1], alone[0]});
  CHECK(reversed.robotNames() == std::vector<std::string>{"cf0", "cf1"});
}

TEST_CASE("vector environment: copies left out of a step or a reset keep every bit, a reset's seed decides the noise",
          "[learn]") {
  VectorEnvironment v([](std::size_t) { return crazyflies(); }, 4, 2);
  v.step(400);  // hovering
  const std::vector<std::byte> start = v[0].saveState();
  const auto before = hashes(v);
  const std::array<std::uint8_t, 4> active{1, 0, 1, 0};
  v.step(50, active);
  auto after = hashes(v);
  CHECK(after[1] == before[1]);
  CHECK(after[3] == before[3]);
  CHECK(after[0] != before[0]);
  CHECK(after[0] == after[2]);
  // copies 0 and 2 back to the start, reseeded alike; copy 1 with another seed; copy 3 untouched
  const std::array<std::size_t, 3> which{0, 1, 2};
  const std::array<std::uint64_t, 3> seeds{11, 12, 11};
  v.reset(which, start, seeds);
  CHECK(hashes(v)[0] == before[0]);
  CHECK(v[0].stepCount() == 400);
  CHECK(hashes(v)[3] == after[3]);
  v.step(200);
  after = hashes(v);
  CHECK(after[0] == after[2]);  // the same seed: the same noise, the same flight
  CHECK(after[0] != after[1]);  // another seed: the pose sensor's noise differs, so does the flight
  // a state that is not this scene's: refused before any copy changes
  Scene other = crazyflies(2);
  other.environment->start();
  const std::vector<std::byte> foreign = other.environment->saveState();
  const std::array<std::size_t, 1> first{0};
  const std::array<std::uint64_t, 1> one{1};
  CHECK_THROWS_AS(v.reset(first, foreign, one), StateError);
  CHECK(hashes(v) == after);
  const std::array<std::size_t, 2> twice{1, 1};
  const std::array<std::uint64_t, 2> two{1, 2};
  CHECK_THROWS_WITH(v.reset(twice, start, two), Contains("copy 1 twice"));
  CHECK_THROWS_WITH(v.reset(first, start, two), Contains("one seed per copy"));
}

TEST_CASE("vector environment: states and IMU readings in one array, commands checked whole, robots moved", "[learn]") {
  VectorEnvironment v([](std::size_t) { return crazyflies(2); }, 3, 2);
  v.step(1500);
  std::vector<double> states(3 * 2 * kRobotStateSize), imu(3 * 2 * 6);
  v.robotStates(states);
  v.imuReadings(imu);
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t r = 0; r < 2; ++r) {
      const double* s = &states[(c * 2 + r) * kRobotStateSize];
      const BodyState truth = v[c].findArtifact(v.robotNames()[r])->state();
      CHECK(s[0] == truth.pose.position.x());
      CHECK(s[2] == truth.pose.position.z());
      CHECK(s[3] == truth.pose.orientation.w());
      CHECK(s[9] == truth.linear_velocity.z());
      CHECK(s[2] == Approx(1.05).margin(0.25));                     // taken off to about 1 m up
      CHECK(imu[(c * 2 + r) * 6 + 2] == Approx(9.81).margin(1.0));  // the accelerometer reads +g
    }
  CHECK_THROWS_WITH(v.robotStates(std::span<double>(states).first(5)), Contains("3 x 2 x 13"));
  // velocity commands for all six robots; a NaN in the last row refuses the whole batch
  std::vector<double> commands(3 * 2 * 4, 0.0);
  commands[0] = 0.5;  // copy 0, robot cf0: 0.5 m/s along x
  commands.back() = std::nan("");
  CHECK_THROWS_WITH(v.setCommands(CommandLevel::Velocity, commands, 4), Contains("copy 2, robot 'cf1'"));
  commands.back() = 0;
  const std::vector<double> wheels(3 * 2 * 2, 0.0);  // a quadrotor has none
  CHECK_THROWS_WITH(v.setCommands(CommandLevel::Wheels, wheels, 2), Contains("copy 0, robot 'cf0'"));
  CHECK_THROWS_WITH(v.setCommands(CommandLevel::Velocity, commands, 3), Contains("rows of 3"));
  v.setCommands(CommandLevel::Velocity, commands, 4);
  v.step(500);
  v.robotStates(states);
  CHECK(states[7] == Approx(0.5).margin(0.1));          // copy 0, cf0 flies at 0.5 m/s
  CHECK(std::abs(states[kRobotStateSize + 7]) < 0.05);  // cf1 holds
  // copy 1's robots moved 0.2 m up and set moving at 0.3 m/s along y
  std::vector<double> before(states);
  const std::array<std::size_t, 1> which{1};
  const std::vector<double> offsets{0, 0, 0.2, 0, 0, 0.2}, velocities{0, 0.3, 0, 0, 0.3, 0};
  v.moveRobots(which, offsets, velocities);
  v.robotStates(states);
  const std::size_t copy1 = 2 * kRobotStateSize;
  CHECK(states[copy1 + 2] == Approx(before[copy1 + 2] + 0.2));
  CHECK(states[copy1 + 8] == 0.3);
  CHECK(states[2] == before[2]);  // copy 0 unmoved
  CHECK_THROWS_WITH(v.moveRobots(which, std::vector<double>(3, 0.0), {}), Contains("1 x 2 x 3"));
}

TEST_CASE("vector environment: copies must be one scene, each on one thread", "[learn]") {
  CHECK_THROWS_WITH(VectorEnvironment([](std::size_t i) { return crazyflies(1, 4, i == 0 ? "cf{i}" : "other{i}"); }, 2),
                    Contains("copy 1 of a vector environment has other robots than copy 0: robot 0 is 'other0'"));
  CHECK_THROWS_WITH(VectorEnvironment(
                        [](std::size_t) {
                          SceneOptions options;
                          options.threads = 2;
                          return loadSceneFromString("<scene><ground/></scene>", "two.xml", ".", options);
                        },
                        1),
                    Contains("load each copy with one"));
  CHECK_THROWS_AS(VectorEnvironment([](std::size_t) { return crazyflies(); }, 0), ConfigError);
  // the same robots, but copy 1 has a ground too: not one scene (a state of one would not fit the other)
  CHECK_THROWS_WITH(VectorEnvironment(
                        [](std::size_t i) {
                          SceneOptions options;
                          options.threads = 1;
                          return loadSceneFromString(
                              "<scene><environment timestep=\"0.002\"/><type name=\"cf\" file=\"" +
                                  (kArtifacts / "crazyflie.xml").string() + "\"/>" + (i == 1 ? "<ground/>" : "") +
                                  "<artifact type=\"cf\" name=\"cf0\" xyz=\"0 0 1\"/></scene>",
                              "cf.xml", kArtifacts, options);
                        },
                        2),
                    Contains("copy 1 of a vector environment is not the same scene as copy 0"));
}

TEST_CASE("vector environment: constants varied per copy and robot, checked whole, the others untouched", "[learn]") {
  VectorEnvironment v([](std::size_t) { return crazyflies(2); }, 3, 2);
  v.step(500);
  const std::vector<std::byte> hovering = v[0].saveState();
  // the same variation made on one environment alone: the copy varied ends as it does
  Scene alone = crazyflies(2);
  alone.environment->restoreState(hovering);
  alone.environment->vary(*alone.environment->findArtifact("cf1"), "mass", 1.3);
  alone.environment->step(200);
  const auto untouched = hashes(v);

  const std::array<std::size_t, 1> which{1};
  const std::array<double, 2> values{1.0, 1.3};  // cf0 as it is, cf1 heavier
  v.vary(which, "mass", values);
  CHECK(v[1].variation(*v[1].findArtifact("cf1"), "mass") == 1.3);
  CHECK(v[0].variation(*v[0].findArtifact("cf1"), "mass") == 1.0);
  std::vector<std::string> names;
  for (const Variable& x : v.variables(0)) names.emplace_back(x.name);
  CHECK(std::find(names.begin(), names.end(), "thrust_coefficient") != names.end());
  v.step(200);
  CHECK(hashes(v)[1] == alone.environment->stateHash());
  Scene plain = crazyflies(2);
  plain.environment->restoreState(hovering);
  plain.environment->step(200);
  CHECK(hashes(v)[0] == plain.environment->stateHash());
  CHECK(hashes(v)[2] == plain.environment->stateHash());
  CHECK(untouched[0] != hashes(v)[0]);

  // refused whole: a bad value in the last row changes nothing in the first
  const auto now = hashes(v);
  const std::array<std::size_t, 2> both{0, 2};
  const std::array<double, 4> bad{1.1, 1.1, 1.1, 40.0};
  CHECK_THROWS_WITH(v.vary(both, "mass", bad), Contains("copy 2, robot 'cf1': mass must be within"));
  CHECK(v[0].variation(*v[0].findArtifact("cf0"), "mass") == 1.0);
  CHECK_THROWS_WITH(v.vary(both, "thrust", std::array<double, 4>{1, 1, 1, 1}),
                    Contains("robot 'cf0' has no constant 'thrust'"));
  CHECK_THROWS_WITH(v.vary(std::array<std::size_t, 2>{0, 0}, "mass", std::array<double, 4>{1, 1, 1, 1}),
                    Contains("names copy 0 twice"));
  CHECK_THROWS_WITH(v.vary(both, "mass", std::array<double, 2>{1, 1}), Contains("needs 2 x 2 values"));
  CHECK(hashes(v) == now);
}

TEST_CASE("vector environment: a command delayed by some steps takes effect then, as one copy alone would",
          "[learn]") {
  auto load = [](std::size_t) { return crazyflies(2); };
  const std::vector<double> tilt = {0.2, 0, 0, 0.3, 0.1, 0, 0, 0.3};  // attitude rows: roll, pitch, yaw rate, thrust
  // the same by hand, in one environment: 3 steps on the old commands, then robot 0's, 4 more, then robot 1's
  Scene alone = crazyflies(2);
  Environment& env = *alone.environment;
  env.step(400);
  auto commands = [&](std::size_t r) { return dynamic_cast<CommandInterface*>(env.findArtifact("cf" + std::to_string(r))->driver()); };
  env.step(3);
  commands(0)->setCommand(Command::fromRow(CommandLevel::Attitude, std::span(tilt).first(4)));
  env.step(4);
  commands(1)->setCommand(Command::fromRow(CommandLevel::Attitude, std::span(tilt).subspan(4)));
  env.step(13);
  for (const int threads : {1, 2}) {
    VectorEnvironment v(load, 2, threads);
    v.step(400);
    const std::vector<std::byte> start = v[0].saveState();
    const std::array<std::size_t, 1> second{1};
    const std::array<std::int64_t, 2> delays{3, 7};
    v.setCommandDelays(second, delays);
    std::vector<double> rows(tilt);
    rows.insert(rows.end(), tilt.begin(), tilt.end());
    v.setCommands(CommandLevel::Attitude, rows, 4);
    v.step(2);  // (robot 0's is due within the next call)
    v.step(18);
    CHECK(v[1].stateHash() == env.stateHash());
    CHECK(v[0].stateHash() != env.stateHash());  // copy 0: no delay
    // a reset drops the commands waiting: the copy goes on from the state restored as one that was never commanded
    const std::array<std::size_t, 2> both{0, 1};
    const std::array<std::uint64_t, 2> seeds{9, 9};
    v.reset(both, start, seeds);
    v.setCommands(CommandLevel::Attitude, rows, 4);
    v.reset(both, start, seeds);
    v.step(20);
    CHECK(v[1].stateHash() != env.stateHash());
    CHECK(v[0].stateHash() == v[1].stateHash());  // copy 0's commands were sent at once, then restored over too
    // refused before anything changes
    const std::array<std::int64_t, 2> negative{0, -1};
    CHECK_THROWS_WITH(v.setCommandDelays(second, negative), Contains("copy 1, robot 'cf1'") && Contains(">= 0"));
    CHECK_THROWS_WITH(v.setCommandDelays(second, std::span(delays).first(1)), Contains("need 2 numbers, got 1"));
  }
}

TEST_CASE("vector environment: a learning step in one pass over each copy is commands, steps and readings in turn",
          "[learn]") {
  // two batches of the same copies, one stepped in one pass, the other call by call as a learning
  // loop did: commands to all, the resets, the steps of the copies not reset, the readings
  auto load = [](std::size_t) { return crazyflies(2); };
  const std::size_t copies = 4, robots = 2;
  for (const int threads : {1, 2}) {
    VectorEnvironment fused(load, copies, threads), apart(load, copies, 1);
    fused.step(400);
    apart.step(400);
    const std::vector<std::byte> start = fused[0].saveState();
    // copy 1's robots take commands 3 and 5 steps late (the commands waiting are per copy)
    const std::array<std::size_t, 1> late{1};
    const std::array<std::int64_t, 2> delays{3, 5};
    fused.setCommandDelays(late, delays);
    apart.setCommandDelays(late, delays);
    std::vector<double> commands(copies * robots * 4), states(copies * robots * kRobotStateSize),
        imu(copies * robots * 6), states_apart(states.size()), imu_apart(imu.size());
    std::uint64_t lcg = 7;
    auto draw = [&lcg] {
      lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
      return static_cast<double>(lcg >> 11) * 0x1p-53 - 0.5;
    };
    for (int batch = 0; batch < 30; ++batch) {
      for (std::size_t k = 0; k < commands.size(); k += 4)  // attitude rows: roll, pitch, yaw rate, thrust
        commands[k] = 0.2 * draw(), commands[k + 1] = 0.2 * draw(), commands[k + 2] = draw(),
        commands[k + 3] = 0.3 + 0.05 * draw();
      // every seventh batch copies 1 and 2 start again, and stay where they are for that batch
      std::vector<std::uint8_t> active(copies, 1);
      std::vector<std::size_t> resetting;
      if (batch % 7 == 6) resetting = {1, 2};
      const std::vector<std::uint64_t> seeds(resetting.size(), static_cast<std::uint64_t>(batch));
      for (const std::size_t i : resetting) active[i] = 0;
      apart.setCommands(CommandLevel::Attitude, commands, 4);
      apart.reset(resetting, start, seeds);
      apart.step(10, active);
      apart.robotStates(states_apart);
      apart.imuReadings(imu_apart);
      fused.checkCommands(CommandLevel::Attitude, commands, 4);
      fused.reset(resetting, start, seeds);
      fused.step(10, active, {CommandLevel::Attitude, commands, 4, states, imu});
      CHECK(hashes(fused) == hashes(apart));
      CHECK(states == states_apart);
      CHECK(imu == imu_apart);
    }
    CHECK(fused[1].stateHash() != fused[3].stateHash());  // (the commands and their delays made a difference)
    // refused whole before any copy changes: a NaN in the last row, outputs of the wrong size
    const std::vector<std::uint64_t> before = hashes(fused);
    commands.back() = std::nan("");
    CHECK_THROWS_WITH(fused.step(10, {}, {CommandLevel::Attitude, commands, 4, states, imu}),
                      Contains("copy 3, robot 'cf1'"));
    commands.back() = 0.3;
    CHECK_THROWS_WITH(fused.step(10, {}, {CommandLevel::Attitude, commands, 4, std::span(states).first(13), imu}),
                      Contains("robotStates needs 4 x 2 x 13"));
    CHECK_THROWS_WITH(fused.step(10, {}, {CommandLevel::Attitude, commands, 4, states, std::span(imu).first(6)}),
                      Contains("imuReadings needs 4 x 2 x 6"));
    CHECK(hashes(fused) == before);
  }
}

TEST_CASE("vector environment: a copy's hot memory holds its artifacts, plugins and bodies, a large world lists none",
          "[learn]") {
  // what VectorEnvironment asks the processor for, for the next copy while one steps
  Scene small = crazyflies(2);
  Environment& env = *small.environment;
  env.start();
  std::vector<MemoryRange> ranges;
  env.hotMemory(ranges);
  auto holds = [&ranges](const void* p) {
    return std::any_of(ranges.begin(), ranges.end(), [p](const MemoryRange& r) {
      const auto* begin = static_cast<const char*>(r.address);
      return static_cast<const char*>(p) >= begin && static_cast<const char*>(p) < begin + r.bytes;
    });
  };
  for (std::size_t a = 0; a < env.artifactCount(); ++a) {
    const Artifact& artifact = std::as_const(env).artifact(a);
    CHECK(holds(&artifact));
    if (artifact.driver() != nullptr) CHECK(holds(artifact.driver()));
    for (std::size_t k = 0; k < artifact.sensorCount(); ++k) CHECK(holds(&artifact.sensor(k)));
  }
  const std::size_t before = ranges.size();
  CHECK(before > 10);  // the world's tables and the engine's bodies and geoms besides
  env.step(10);
  std::vector<MemoryRange> again;
  env.hotMemory(again);
  CHECK(again.size() == before);
  Scene large = crazyflies(17);
  large.environment->start();
  std::vector<MemoryRange> none;
  large.environment->hotMemory(none);
  CHECK(none.empty());
}
