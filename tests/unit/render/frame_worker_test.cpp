// The frame worker: scene cameras' frames are drawn on a thread of their own, every frame queued is
// drawn, in order, before the run's stop returns, and the worker's signal handling stays on its own
// thread (the embedding program's signal mask is left as it was).
// Headless (OSMesa); every test name contains "render".
#include <ssx/ssx.hpp>

#include "render_util.hpp"

#include <catch2/catch.hpp>

#include <csignal>
#include <filesystem>
#include <pthread.h>

using namespace ssx;
using namespace ssx::test;
namespace fs = std::filesystem;

TEST_CASE("render: the frame worker draws every queued frame before stop returns, numbered in order",
          "[render][frame_worker]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  const fs::path dir = fs::current_path() / "worker_frames";
  fs::remove_all(dir);
  Scene s = loadRenderScene(R"(<render engine="osmesa" rate_hz="100" width="32" height="24">
      <camera name="side" xyz="0 -6 2" look_at="0 0 1" frames=")" + dir.string() + R"("/>
    </render><ground/>
    <type name="ball" file="yellow_ball.xml"/><artifact name="ball" type="ball" xyz="0 0 2"/>)");
  s.environment->step(1000);  // 2 s at 100 frames per simulated second: 200 frames
  s.environment->stop();     // drains the queue: nothing may be missing after it
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.path().extension() == ".png" ? 1 : 0;
  CHECK(files == 200);
  CHECK(fs::exists(dir / "frame_000000.png"));
  CHECK(fs::exists(dir / "frame_000199.png"));
  CHECK_FALSE(fs::exists(dir / "frame_000200.png"));
  // the ball falls: the first frame and the last differ
  CHECK(fileText(dir / "frame_000000.png") != fileText(dir / "frame_000199.png"));
}

TEST_CASE("render: drawing frames leaves the stepping thread's signal mask as it was", "[render][frame_worker]") {
  REQUIRE(haveOsmesa());
  sigset_t before;
  REQUIRE(pthread_sigmask(SIG_BLOCK, nullptr, &before) == 0);
  REQUIRE_FALSE(sigismember(&before, SIGPIPE));
  {
    Scene s = loadRenderScene(R"(<render engine="osmesa" rate_hz="10" width="32" height="24">
        <camera name="side" xyz="0 -6 2" look_at="0 0 1" frames=")" + (fs::current_path() / "mask_frames").string() +
                              R"("/></render><ground/>)");
    s.environment->step(100);
    s.environment->stop();
  }
  sigset_t after;
  REQUIRE(pthread_sigmask(SIG_BLOCK, nullptr, &after) == 0);
  CHECK_FALSE(sigismember(&after, SIGPIPE));
}
