// Saved states (world_state.cpp): what does not fit the world is refused and changes nothing.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"
#include "state_scene.hpp"
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <cstring>
#include <string>
#include <vector>

using namespace ssx;

using ssx::test::kArtifacts;
using ssx::test::loadStateScene;

TEST_CASE("a truncated, corrupted or foreign state is refused and changes nothing", "[state]") {
  Scene scene = loadStateScene(2);
  Environment& env = *scene.environment;
  env.step(100);
  const std::vector<std::byte> saved = env.saveState();
  env.step(50);
  const std::vector<std::byte> at150 = env.saveState();
  const std::uint64_t before = env.stateHash();

  std::vector<std::byte> truncated(saved.begin(), saved.end() - 1);
  std::vector<std::byte> corrupted = saved;
  corrupted[corrupted.size() / 2] ^= std::byte{0x10};
  Scene other = loadSceneFromString(
      "<scene><type name=\"box\" file=\"box.xml\"/><artifact name=\"b\" type=\"box\"/></scene>", "other.xml", kArtifacts);
  other.environment->step(3);
  const std::vector<std::byte> foreign = other.environment->saveState();

  CHECK_THROWS_AS(env.restoreState(truncated), StateError);
  CHECK_THROWS_WITH(env.restoreState(truncated), Catch::Contains("truncated"));
  CHECK_THROWS_WITH(env.restoreState(corrupted), Catch::Contains("corrupted (checksum mismatch)"));
  CHECK_THROWS_WITH(env.restoreState(foreign), Catch::Contains("saved from a different scene"));
  // the same scene loaded on the other engine: the state names its engine, and the restore
  // switches to it and goes on as the run that saved it
  Scene on_bullet = loadStateScene(2, "", "bullet");
  on_bullet.environment->restoreState(saved);
  CHECK(on_bullet.environment->physics().name() == "ode");
  CHECK(on_bullet.environment->physicsSwitches().empty());  // (the state says its engine: no switch asked for)
  on_bullet.environment->step(50);
  CHECK(on_bullet.environment->saveState() == at150);
  CHECK_THROWS_WITH(env.restoreState(std::vector<std::byte>(10)), Catch::Contains("not an ssx saved state"));
  // nothing moved: the world is still at step 150 and goes on as it would have
  CHECK(env.stepCount() == 150);
  CHECK(env.stateHash() == before);
  CHECK(env.saveState() == at150);
}

TEST_CASE("the scene's physics partitions are part of the state: a restore needs the same count", "[state]") {
  auto scene = [](const std::string& physics) {
    return loadSceneFromString("<scene>" + physics + "<ground/><type name=\"box\" file=\"box.xml\"/>"
                               "<swarm type=\"box\" count=\"150\" name=\"b{i}\" spacing=\"1\" xyz=\"0 0 0.5\"/></scene>",
                               "partitions.xml", kArtifacts);
  };
  Scene three = scene("<physics partitions=\"3\"/>");
  three.environment->step(20);
  const std::vector<std::byte> saved = three.environment->saveState();
  Scene again = scene("<physics partitions=\"3\"/>");
  again.environment->start();
  again.environment->restoreState(saved);
  CHECK(again.environment->stateHash() == three.environment->stateHash());
  Scene sixteen = scene("");  // the default, 16
  sixteen.environment->start();
  CHECK_THROWS_AS(sixteen.environment->restoreState(saved), StateError);
}

namespace {

// a driver whose loadState reads less than its saveState wrote
class ForgetfulDriver final : public Driver {
 public:
  void step(const StepInfo&) override { ++runs_; }
  void saveState(StateWriter& out) const override {
    out.write(runs_);
    out.write(runs_);
  }
  void loadState(StateReader& in) override { in.read(runs_); }
  std::int64_t runs_ = 0;
};

}  // namespace

TEST_CASE("a plugin that reads back less than it saved fails the restore, which changes nothing", "[state]") {
  Environment env;
  Artifact& a = env.addArtifact("body", test::at(0, 0, 1));
  a.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
  auto& driver = static_cast<ForgetfulDriver&>(a.setDriver(std::make_unique<ForgetfulDriver>()));
  env.step(10);
  const auto saved = env.saveState();
  env.step(5);
  const auto hash = env.stateHash();
  CHECK_THROWS_WITH(env.restoreState(saved), Catch::Contains("driver 'driver' of artifact 'body' left 8 bytes"));
  CHECK(env.stepCount() == 15);
  CHECK(env.stateHash() == hash);
  CHECK(driver.runs_ == 15);
}

namespace {

// a driver whose loadState takes the count it saved, then refuses 13 (after taking it)
class PickyDriver final : public Driver {
 public:
  void step(const StepInfo&) override { ++runs_; }
  void saveState(StateWriter& out) const override { out.write(runs_); }
  void loadState(StateReader& in) override {
    in.read(runs_);
    if (runs_ == 13) throw StateError("13 refused");
  }
  std::int64_t runs_ = 0;
};

}  // namespace

TEST_CASE("a state restored again continues the same, and another that fails still changes nothing", "[state]") {
  Environment env;
  Artifact& a = env.addArtifact("body", test::at(0, 0, 1));
  a.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
  auto& driver = static_cast<PickyDriver&>(a.setDriver(std::make_unique<PickyDriver>()));
  env.step(10);
  const auto at10 = env.saveState();
  env.step(3);
  const auto at13 = env.saveState();
  env.step(2);
  // the first restore of these bytes keeps a copy to fall back on; the next ones need none
  env.restoreState(at10);
  env.step(5);
  const auto hash = env.stateHash();
  for (int k = 0; k < 2; ++k) {
    env.restoreState(at10);
    CHECK(driver.runs_ == 10);
    env.step(5);
    CHECK(env.stateHash() == hash);
  }
  // other bytes, refused half way: put back as they were
  CHECK_THROWS_WITH(env.restoreState(at13), Catch::Contains("13 refused"));
  CHECK(driver.runs_ == 15);
  CHECK(env.stepCount() == 15);
  CHECK(env.stateHash() == hash);
}

TEST_CASE("format 8's checksum catches a changed word anywhere, and format 6's states are still read", "[state]") {
  Scene scene = loadStateScene(2);
  Environment& env = *scene.environment;
  env.step(100);
  const std::vector<std::byte> saved = env.saveState();
  env.step(50);
  const std::vector<std::byte> at150 = env.saveState();
  constexpr std::size_t kHeader = 40;
  std::uint32_t version = 0;
  std::memcpy(&version, saved.data() + 8, 4);
  CHECK(version == 8);
  // a bit changed in each of the four lanes' words, and in the bytes past the last whole 32
  for (const std::size_t at : {kHeader, kHeader + 9, kHeader + 18, kHeader + 31, saved.size() - 1}) {
    std::vector<std::byte> changed = saved;
    changed[at] ^= std::byte{0x80};
    INFO(at);
    CHECK_THROWS_WITH(env.restoreState(changed), Catch::Contains("corrupted (checksum mismatch)"));
  }
  // the same payload as format 6 wrote it (without format 8's count of artifacts out of the world,
  // 0 here, at its end), summed byte by byte with FNV-1a: restored as it was
  std::uint64_t absent = ~std::uint64_t{0};
  std::memcpy(&absent, saved.data() + saved.size() - 8, 8);
  REQUIRE(absent == 0);
  std::vector<std::byte> six(saved.begin(), saved.end() - 8);
  const std::uint32_t format6 = 6;
  const std::uint64_t payload = six.size() - kHeader;
  std::memcpy(six.data() + 8, &format6, 4);
  std::memcpy(six.data() + 24, &payload, 8);
  const std::uint64_t sum = fnv1a(six.data() + kHeader, six.size() - kHeader);
  std::memcpy(six.data() + 32, &sum, 8);
  env.restoreState(six);
  env.step(50);
  CHECK(env.saveState() == at150);
  // an earlier format is refused, naming the ones read
  std::vector<std::byte> five = six;
  const std::uint32_t format5 = 5;
  std::memcpy(five.data() + 8, &format5, 4);
  CHECK_THROWS_WITH(env.restoreState(five), Catch::Contains("saved state format 5, this ssx reads formats 6 to 8"));
}

TEST_CASE("a state saved over a kept buffer is the state saved afresh, whatever the buffer held", "[state]") {
  Scene scene = loadStateScene(2);
  Environment& env = *scene.environment;
  env.step(20);
  const std::vector<std::byte> fresh = env.saveState();
  // longer than the state and full of other bytes: written over and trimmed
  std::vector<std::byte> kept(fresh.size() + 4096, std::byte{0xAB});
  env.saveState(kept);
  CHECK(kept == fresh);
  // shorter (grown while written), and empty
  std::vector<std::byte> short_one(100, std::byte{0x5C}), empty;
  env.saveState(short_one);
  env.saveState(empty);
  CHECK(short_one == fresh);
  CHECK(empty == fresh);
  // the kept buffer, restored, continues as the run did
  env.step(30);
  const std::vector<std::byte> at50 = env.saveState();
  env.restoreState(kept);
  env.step(30);
  env.saveState(kept);
  CHECK(kept == at50);
}

TEST_CASE("a state writer writing over a buffer keeps what is before its start, grows and trims", "[state]") {
  std::vector<std::byte> buffer(8, std::byte{7});
  {
    StateWriter out(buffer, 3);
    CHECK(out.size() == 3);
    out.write(std::uint32_t{0x01020304});  // fits: 3 + 4 of 8
    CHECK(out.size() == 7);
    out.write(std::string(50, 'x'));  // does not: grown
    CHECK(out.size() == 7 + 8 + 50);
    CHECK(buffer.size() >= out.size());
  }  // (trimmed when the writer ends)
  REQUIRE(buffer.size() == 65);
  CHECK(buffer[0] == std::byte{7});
  CHECK(buffer[2] == std::byte{7});
  StateReader in(std::span<const std::byte>(buffer).subspan(3));
  CHECK(in.get<std::uint32_t>() == 0x01020304u);
  std::string text;
  in.read(text);
  CHECK(text == std::string(50, 'x'));
  CHECK(in.done());
  // a start past the end grows the buffer to it; one made on a vector alone appends as before
  std::vector<std::byte> small(2);
  StateWriter past(small, 5);
  CHECK(small.size() == 5);
  past.finish();
  StateWriter append(small);
  append.write(std::uint8_t{9});
  CHECK(small.size() == 6);
  CHECK(small[5] == std::byte{9});
}
