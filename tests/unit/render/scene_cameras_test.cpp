// Scene cameras: numbered PNG frames at the render rate and a snapshot at the end.
// Headless (OSMesa); every test name contains "render".
#include <ssx/ssx.hpp>

#include "render_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

using namespace ssx;
using namespace ssx::test;
namespace fs = std::filesystem;

TEST_CASE("render: scene cameras write numbered PNG frames at their rate and a snapshot at the end", "[render]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  const fs::path dir = fs::current_path() / "render";
  fs::remove_all(dir);
  Scene s = loadRenderScene(R"(<render engine="osmesa" rate_hz="10" width="160" height="120">
      <camera name="side" xyz="0 -6 2" look_at="0 0 1" frames=")" + (dir / "side").string() + R"(" snapshot=")" +
                 (dir / "snap.png").string() + R"("/>
      <camera name="chase" follow="ball" xyz="-3 0 1" look_at="0 0 0"/>
    </render><ground/>
    <type name="ball" file="yellow_ball.xml"/><artifact name="ball" type="ball" xyz="0 0 2"/>)");
  Environment& env = *s.environment;
  env.step(250);  // 0.5 s at 10 frames per simulated second: steps 0, 50, ..., 200
  CHECK(env.frameCount() == 5);
  env.stop();
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir / "side")) files += e.path().extension() == ".png" ? 1 : 0;
  CHECK(files == 5);
  CHECK(fs::exists(dir / "side" / "frame_000004.png"));
  // a PNG of the size asked for: signature, then IHDR with width and height big-endian
  std::ifstream png(dir / "snap.png", std::ios::binary);
  unsigned char head[24] = {};
  png.read(reinterpret_cast<char*>(head), sizeof head);
  CHECK(std::memcmp(head, "\x89PNG\r\n\x1a\n", 8) == 0);
  CHECK(((head[16] << 24) | (head[17] << 16) | (head[18] << 8) | head[19]) == 160);
  CHECK(((head[20] << 24) | (head[21] << 16) | (head[22] << 8) | head[23]) == 120);
}
