// What is attached to a run and taken off again without changing it (observers.cpp): renderers
// drawing the scene cameras' frames (Environment::attachRenderer, detachRenderer, the window
// RenderSettings::from/until) and extensions attached as observers (attachExtension,
// removeExtension while running). A run with a renderer attached at 1 s and detached at 2 s, and
// one with an observer, are bitwise the run without them; their states restore into each other.
#include "render_util.hpp"
#include "scene_util.hpp"
#include "test_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

using namespace ssx;
using namespace ssx::test;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

// nine mk_quads take off from the ground and hold 1 m above where they started
Scene hoverSwarm(int threads = 1, const std::string& render = "") {
  return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"5\" threads=\"" +
                                 std::to_string(threads) + "\"/>" + render + "<type name=\"quad\" file=\"" +
                                 (kArtifacts / "mk_quad.xml").string() +
                                 "\"/><ground/><swarm type=\"quad\" count=\"9\" layout=\"grid\" spacing=\"1.5\" "
                                 "xyz=\"0 0 0.05\"><driver offset=\"0 0 1\"/></swarm></scene>",
                             "hover.xml", kArtifacts);
}

int pngFiles(const fs::path& dir) {
  int n = 0;
  if (fs::exists(dir))
    for (const auto& e : fs::directory_iterator(dir)) n += e.path().extension() == ".png" ? 1 : 0;
  return n;
}

// frames of a camera framing the scene into `dir`, with a snapshot, `rate_hz` per simulated second
RenderSettings framesInto(const fs::path& dir, double rate_hz) {
  RenderSettings r;
  r.engine = "osmesa";
  r.rate_hz = rate_hz;
  r.width = 96;
  r.height = 64;
  CameraSpec camera;
  camera.frame_scene = true;
  camera.frames_dir = dir / "frames";
  camera.snapshot = dir / "last.png";
  r.cameras.push_back(camera);
  return r;
}

// counts its hooks; its saved state (one byte) must never be asked for while it observes
class Watcher final : public SimulationExtension {
 public:
  int inits = 0, steps = 0, shutdowns = 0;
  bool throw_at_init = false;
  std::function<void(Environment&)> at_step;
  void init(Environment&, const Descriptor&) override {
    if (throw_at_init) throw ConfigError({}, "watcher: refused");
    ++inits;
  }
  void afterStep(Environment& env) override {
    ++steps;
    if (at_step) at_step(env);
  }
  void shutdown(Environment&) override { ++shutdowns; }
  void saveState(StateWriter& out) const override { out.write(std::uint8_t{7}); }
  void loadState(StateReader& in) override { in.get<std::uint8_t>(); }
};

}  // namespace

TEST_CASE("render attach: a renderer attached at 1 s and detached at 2 s draws its frames and changes no bit",
          "[observers][render]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  const fs::path dir = fs::current_path() / "attached";
  fs::remove_all(dir);
  Scene watched = hoverSwarm(2);
  Scene plain = hoverSwarm(1);  // never drawn
  Environment& env = *watched.environment;
  Environment& ref = *plain.environment;
  env.step(500);
  ref.step(500);
  CHECK(env.cameras().empty());
  env.attachRenderer(framesInto(dir, 25));  // 25 frames per simulated second: every 20 steps
  CHECK(env.cameras().size() == 1);         // opened at once, placed around the swarm as it is now
  env.step(500);
  ref.step(500);
  CHECK(env.frameCount() == 25);
  env.detachRenderer();
  // the outputs are finished when it comes off, not at the end of the run
  CHECK(pngFiles(dir / "frames") == 25);
  CHECK(readPng(dir / "last.png").width == 96);
  CHECK(env.cameras().empty());
  env.step(250);
  ref.step(250);
  CHECK(env.frameCount() == 25);
  CHECK(env.stateHash() == ref.stateHash());
  CHECK(env.saveState() == ref.saveState());
  // and again, into another directory: the run goes on the same
  env.attachRenderer(framesInto(dir / "again", 50));
  env.step(50);
  ref.step(50);
  CHECK(env.frameCount() == 25 + 5);  // every 10 steps from the next one: steps 0, 10, ..., 40 after attaching
  env.stop();
  CHECK(pngFiles(dir / "again" / "frames") == 5);
  CHECK(env.stateHash() == ref.stateHash());
}

TEST_CASE("render attach: frames in a window of simulated time are drawn from its start to its end, outputs finished then",
          "[observers][render]") {
  REQUIRE(haveOsmesa());
  const fs::path dir = fs::current_path() / "window";
  fs::remove_all(dir);
  Scene s = hoverSwarm(1);
  Environment& env = *s.environment;
  RenderSettings r = framesInto(dir, 25);
  r.from = toNanoseconds(0.5);
  r.until = toNanoseconds(1.0);
  env.attachRenderer(r);  // before start: what the run starts with
  env.step(249);          // up to 0.498 s: nothing drawn, nothing opened
  CHECK(env.frameCount() == 0);
  CHECK(env.cameras().empty());
  CHECK_FALSE(fs::exists(dir / "frames"));
  env.step(1);  // the step ending at 0.5 s: the first frame
  CHECK(env.frameCount() == 1);
  CHECK(env.cameras().size() == 1);
  env.step(250);  // to 1.0 s: frames at 0.5, 0.54, ..., 0.98 s, then finished
  CHECK(env.frameCount() == 13);
  CHECK(env.cameras().empty());
  CHECK(pngFiles(dir / "frames") == 13);
  CHECK(fs::exists(dir / "last.png"));  // written when the window ended, before the run stops
  env.step(100);
  CHECK(env.frameCount() == 13);
}

TEST_CASE("render attach: settings out of range or a camera following no robot are refused, the frames going on",
          "[observers][render]") {
  REQUIRE(haveOsmesa());
  const fs::path dir = fs::current_path() / "refused";
  fs::remove_all(dir);
  Scene s = hoverSwarm(1);
  Environment& env = *s.environment;
  env.step(10);
  env.attachRenderer(framesInto(dir, 50));
  RenderSettings lost = framesInto(dir / "lost", 50);
  lost.cameras.front().follow = "nobody";
  CHECK_THROWS_WITH(env.attachRenderer(lost), Contains("follows 'nobody', which is no artifact"));
  RenderSettings backwards = framesInto(dir / "backwards", 50);
  backwards.from = toNanoseconds(2.0);
  backwards.until = toNanoseconds(1.0);
  CHECK_THROWS_WITH(env.attachRenderer(backwards), Contains("until must not come before from"));
  RenderSettings wide = framesInto(dir / "wide", 50);
  wide.width = kMaxImageSide + 1;
  CHECK_THROWS_AS(env.attachRenderer(wide), ConfigError);
  env.step(20);
  CHECK(env.frameCount() == 2);  // the first renderer draws on
  CHECK_FALSE(fs::exists(dir / "lost"));
  env.stop();
  CHECK_THROWS_WITH(env.attachRenderer(framesInto(dir, 50)), Contains("stopped"));
  CHECK_THROWS_WITH(env.detachRenderer(), Contains("stopped"));
}

TEST_CASE("render attach: camera sensors keep the engine they started with", "[observers][render]") {
  REQUIRE(haveOsmesa());
  Scene s = loadRenderScene(R"(<render engine="osmesa"/><ground/>
      <type name="post" file="camera_post.xml"/><artifact name="eye" type="post" xyz="0 0 1"/>)");
  Environment& env = *s.environment;
  env.step(5);
  RenderSettings none;
  none.engine = "null";
  none.rate_hz = 10;
  CHECK_THROWS_WITH(env.attachRenderer(none), Contains("camera sensors draw with render engine 'osmesa'"));
  env.step(5);  // the sensor still sees
  CHECK(image(env).image.width > 0);
}

TEST_CASE("observers: an extension attached while running observes from the next step, outside saved states",
          "[observers]") {
  Watcher watcher;  // (outliving the environment that calls it)
  Scene watched = hoverSwarm(1);
  Scene plain = hoverSwarm(1);
  Environment& env = *watched.environment;
  Environment& ref = *plain.environment;
  env.step(100);
  ref.step(100);
  env.addExtension("watcher", watcher, Descriptor("watcher", {}));  // while running: attached as an observer
  CHECK(watcher.inits == 1);
  env.step(10);
  ref.step(10);
  CHECK(watcher.steps == 10);
  // not in the state, nor in what a state must match: the states are the same bytes
  const std::vector<std::byte> state = env.saveState();
  CHECK(state == ref.saveState());
  env.restoreState(ref.saveState());
  ref.restoreState(state);
  CHECK(env.removeExtension("watcher"));
  CHECK(watcher.shutdowns == 1);
  CHECK_FALSE(env.removeExtension("watcher"));
  env.step(10);
  ref.step(10);
  CHECK(watcher.steps == 10);
  CHECK(env.stateHash() == ref.stateHash());
}

TEST_CASE("observers: attached before start they start with the run and come off while it goes on", "[observers]") {
  Watcher scene_part, observer, other_part;  // (outliving the environments that call them)
  Scene s = hoverSwarm(1);
  Environment& env = *s.environment;
  env.addExtension("part", scene_part, Descriptor("part", {}));
  env.attachExtension("observer", observer, Descriptor("observer", {}));
  CHECK(observer.inits == 0);
  env.step(3);
  CHECK(observer.inits == 1);
  CHECK(observer.steps == 3);
  // the scene's own extension stays: its state is in every saved state
  CHECK_THROWS_WITH(env.removeExtension("part"), Contains("part of the scene"));
  CHECK(env.removeExtension("observer"));
  env.step(1);
  CHECK(observer.steps == 3);
  CHECK(scene_part.steps == 4);
  // a state saved with the scene's extension in it holds its block; one without the observer restores
  Scene other = hoverSwarm(1);
  other.environment->addExtension("part", other_part, Descriptor("part", {}));
  other.environment->restoreState(env.saveState());
  CHECK(other.environment->stateHash() == env.stateHash());
}

TEST_CASE("observers: attaching is refused inside a step, for a duplicate name or a failing init, changing nothing",
          "[observers]") {
  Watcher refusing, first, second, late;  // (outliving the environment that calls them)
  Scene s = hoverSwarm(1);
  Environment& env = *s.environment;
  env.step(1);
  refusing.throw_at_init = true;
  CHECK_THROWS_WITH(env.attachExtension("refusing", refusing, Descriptor("refusing", {})), Contains("watcher: refused"));
  CHECK(env.extension("refusing") == nullptr);
  env.attachExtension("w", first, Descriptor("w", {}));
  CHECK_THROWS_AS(env.attachExtension("w", second, Descriptor("w", {})), ConfigError);
  // from its own hook: an exchange in the middle of a step is refused (the step fails with it)
  first.at_step = [&](Environment& e) { e.attachExtension("late", late, Descriptor("late", {})); };
  CHECK_THROWS_WITH(env.step(), Contains("between steps"));
  CHECK(late.inits == 0);
}

TEST_CASE("observers: a plugin's extension attached while running gets its parameters checked first", "[observers]") {
  Scene s = hoverSwarm(1);
  Environment& env = *s.environment;
  env.step(1);
  Descriptor params("viewer", {"test", 0});
  params.set("rate_hz", 1000.0).set("port", std::int64_t{0});
  SimulationExtension& viewer = env.classLoader().createExtension("viewer", "viewer");
  CHECK_THROWS_WITH(env.attachExtension("viewer", viewer, params), Contains("rate_hz"));
  CHECK(env.extension("viewer") == nullptr);
  env.step(1);  // the run goes on
  CHECK(env.stepCount() == 2);
}
