// Scene cameras: numbered PNG frames at the render rate and a snapshot at the end, stamped with the
// simulated time, with the robots' shadows.
// Headless (OSMesa); every test name contains "render".
#include <ssx/ssx.hpp>

#include "render/time_stamp.hpp"
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

TEST_CASE("render: a picture asked for switches the osmesa engine on, unless the scene named an engine",
          "[render]") {
  REQUIRE(haveOsmesa());
  const std::string robots = R"(<type name="ball" file="yellow_ball.xml"/><artifact name="ball" type="ball" xyz="0 0 2"/>)";
  SceneOptions options;
  options.snapshot = fs::current_path() / "switched_on.png";
  fs::remove(options.snapshot);
  Scene s = loadSceneFromString("<scene>" + robots + "</scene>", "r.xml", kRenderData, options);
  CHECK(s.environment->settings().render.engine == "osmesa");
  s.environment->step(50);
  s.environment->stop();
  CHECK(fs::file_size(options.snapshot) > 1000);
  // a scene camera's own outputs do the same; a scene that names the null engine keeps it
  Scene named = loadSceneFromString(R"(<scene><render engine="null"><camera name="c" snapshot="none.png"/></render>)" +
                                        robots + "</scene>",
                                    "r.xml", kRenderData);
  CHECK(named.environment->settings().render.engine == "null");
  Scene scene_camera = loadSceneFromString(R"(<scene><render><camera name="c" snapshot="mine.png"/></render>)" + robots +
                                               "</scene>",
                                           "r.xml", kRenderData);
  CHECK(scene_camera.environment->settings().render.engine == "osmesa");
}

TEST_CASE("render: a camera that frames the scene keeps every robot in the image as they fly", "[render]") {
  REQUIRE(haveOsmesa());
  // nine quadrotors on a 3 x 3 grid climb 3 m: framed at the start on the ground, they would leave
  // the image at the top
  Scene s = loadSceneFromString(R"(<scene><environment timestep="0.002"/>
    <render engine="osmesa" rate_hz="10"><camera name="auto"/></render><ground/>
    <type name="q" file=")" + (kData.parent_path().parent_path() / "examples" / "artifacts" / "mk_quad.xml").string() +
                                    R"("/><swarm type="q" count="9" name="q{i}" spacing="2" xyz="0 0 0.05">
    <driver offset="0 0 3"/></swarm></scene>)",
                                "framing.xml", kRenderData);
  Environment& env = *s.environment;
  auto inView = [&] {
    const CameraSpec cam = env.cameras().at(0);
    const Vec3 forward = (cam.look_at - cam.position).normalized();
    const Vec3 right = forward.cross(Vec3::UnitZ()).normalized();
    const Vec3 up = right.cross(forward);
    const double tan_v = std::tan(cam.fov_deg * std::numbers::pi / 360), tan_h = tan_v * 640.0 / 480.0;
    int in = 0;
    for (int i = 0; i < 9; ++i) {
      const Vec3 r = env.findArtifact("q" + std::to_string(i))->pose().position - cam.position;
      const double depth = r.dot(forward);
      in += depth > 0 && std::abs(r.dot(right)) < depth * tan_h && std::abs(r.dot(up)) < depth * tan_v ? 1 : 0;
    }
    return in;
  };
  env.step(1);
  CHECK(inView() == 9);
  const double first_distance = (env.cameras().at(0).position - env.cameras().at(0).look_at).norm();
  env.step(3000);  // 6 s: at 3 m
  REQUIRE(env.findArtifact("q4")->pose().position.z() > 2.5);
  CHECK(inView() == 9);
  CHECK((env.cameras().at(0).position - env.cameras().at(0).look_at).norm() > first_distance);  // it widened
  env.stop();
}

TEST_CASE("render: scene camera frames show the simulated time of their step and the robots' shadows, either can be "
          "turned off", "[render][time_stamp][shadows]") {
  REQUIRE(haveOsmesa());
  auto snapshot = [](const std::string& flags, const std::string& name) {
    const fs::path file = fs::current_path() / name;
    fs::remove(file);
    Scene s = loadRenderScene(R"(<render engine="osmesa" rate_hz="10" width="320" height="240" )" + flags + R"(>
        <camera name="side" xyz="-4 -4 4" look_at="0 0 1" snapshot=")" + file.string() + R"("/>
      </render><ground/>
      <type name="ball" file="yellow_ball.xml"/><artifact name="ball" type="ball" xyz="0 0 3"/>)");
    s.environment->step(250);  // frames at steps 0, 50, ..., 200: the last shows t = 201 * 2 ms
    s.environment->stop();
    return readPng(file);
  };
  const Image plain = snapshot(R"(shadows="false" time_stamp="false")", "plain.png");
  const Image both = snapshot("", "both.png");
  const Image shadow_only = snapshot(R"(time_stamp="false")", "shadow_only.png");
  REQUIRE(plain.width == 320);
  REQUIRE(both.width == 320);
  REQUIRE(shadow_only.width == 320);
  // the stamp is exactly the plain frame stamped with that time, in the corner; nothing else differs
  Image stamped = shadow_only;
  detail::stampTime(stamped, 201 * 2'000'000);
  CHECK(stamped.rgb == both.rgb);
  CHECK(shadow_only.rgb != both.rgb);
  // the shadow: only darker pixels than the plain frame, below the ball in the picture
  int darker = 0, brighter = 0;
  double rows = 0;
  for (int y = 0; y < plain.height; ++y)
    for (int x = 0; x < plain.width; ++x) {
      const std::uint8_t *a = plain.pixel(x, y), *b = shadow_only.pixel(x, y);
      const int drop = (a[0] + a[1] + a[2]) - (b[0] + b[1] + b[2]);
      if (drop > 6) {
        ++darker;
        rows += y;
      }
      brighter += drop < -3 ? 1 : 0;
    }
  CHECK(darker > 50);
  CHECK(brighter == 0);
  CHECK(rows / std::max(darker, 1) > yellowRow(plain));
}
