// Rendering: pixel facts on known scenes, outputs, and that drawing never changes results.
// Headless (OSMesa); every test name contains "render".
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <numbers>
#include <string>

using namespace ssx;
namespace fs = std::filesystem;

namespace {

const fs::path kData = fs::path(SSX_TEST_DATA_DIR) / "valid" / "render";

bool haveOsmesa() {
  const auto names = renderEngineNames();
  return std::find(names.begin(), names.end(), "osmesa") != names.end();
}

Scene load(const std::string& body) {
  return loadSceneFromString("<scene><environment timestep=\"0.002\" threads=\"2\"/>" + body + "</scene>",
                             "render.xml", kData);
}

std::string slurpText(const fs::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const CameraMeasurement& image(Environment& env, const std::string& artifact = "eye") {
  return dynamic_cast<const CameraMeasurement&>(env.findArtifact(artifact)->sensor(0).latest());
}

// centroid of the pixels with strong red and green and little blue (the yellow ball), or -1
double yellowRow(const Image& im) {
  double sum = 0, count = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const std::uint8_t* p = im.pixel(x, y);
      if (p[0] > 120 && p[1] > 100 && p[2] < 60) {
        sum += y;
        ++count;
      }
    }
  return count > 0 ? sum / count : -1;
}

// the osmesa engine alone, outside any scene
std::unique_ptr<RenderEngine> osmesaEngine() {
  RenderSettings settings;
  settings.engine = "osmesa";
  return createRenderEngine(settings);
}

// the red pixels (however dimly lit) of an image, or of one of its columns: how many, mean red
struct Red {
  int count = 0;
  double mean = -1;
};
Red redPixels(const Image& im, int column = -1) {
  Red red;
  double sum = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      if (column >= 0 && x != column) continue;
      const std::uint8_t* p = im.pixel(x, y);
      if (p[0] > 30 && p[1] < 30 && p[2] < 30) {
        ++red.count;
        sum += p[0];
      }
    }
  if (red.count > 0) red.mean = sum / red.count;
  return red;
}

}  // namespace

TEST_CASE("render: a red box in front of the camera fills the centre, at its known depth", "[render]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  Scene s = load(R"(<render engine="osmesa" background="0.2 0.4 0.6"/>
    <type name="post" file="camera_post.xml"/>
    <artifact name="eye" type="post" xyz="0 0 1"/>
    <obstacle name="box" xyz="5 0 1" color="1 0 0"><box size="1 1 1"/></obstacle>)");
  Environment& env = *s.environment;
  env.step();
  const CameraMeasurement& m = image(env);
  REQUIRE(m.image.width == 64);
  REQUIRE(m.image.height == 48);
  const std::uint8_t* c = m.image.pixel(32, 24);
  INFO("centre pixel " << int(c[0]) << " " << int(c[1]) << " " << int(c[2]));
  CHECK(c[0] > 150);
  CHECK(c[1] < 40);
  CHECK(c[2] < 40);
  // the box's near face is at x = 4.5, the camera at x = 0.2
  CHECK(m.image.depthAt(32, 24) == Approx(4.3).epsilon(0.01));
  // a corner pixel misses the box: background colour, depth infinite
  const std::uint8_t* corner = m.image.pixel(0, 0);
  CHECK(std::abs(corner[0] - 51) <= 1);
  CHECK(std::abs(corner[2] - 153) <= 1);
  CHECK(std::isinf(m.image.depthAt(0, 0)));
  CHECK(m.view.pose.position.isApprox(Vec3(0.2, 0, 1)));
}

TEST_CASE("render: an empty scene is all background", "[render]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  Scene s = load(R"(<render engine="osmesa" background="0.2 0.4 0.6"/>
    <type name="post" file="camera_post.xml"/><artifact name="eye" type="post" xyz="0 0 1"/>)");
  Environment& env = *s.environment;
  env.step();
  const Image& im = image(env).image;
  int off = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const std::uint8_t* p = im.pixel(x, y);
      off += (std::abs(p[0] - 51) > 1 || std::abs(p[1] - 102) > 1 || std::abs(p[2] - 153) > 1) ? 1 : 0;
    }
  CHECK(off == 0);
}

TEST_CASE("render: a falling robot moves down in a fixed camera's image", "[render]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  Scene s = load(R"(<render engine="osmesa"/>
    <type name="post" file="camera_post.xml"/><type name="ball" file="yellow_ball.xml"/>
    <artifact name="eye" type="post" xyz="0 0 1"/>
    <artifact name="ball" type="ball" xyz="6 0 2"/>)");
  Environment& env = *s.environment;
  env.step();
  const double row_before = yellowRow(image(env).image);
  env.step(250);  // 0.5 s: 1.2 m lower
  const double row_after = yellowRow(image(env).image);
  INFO("rows " << row_before << " -> " << row_after);
  REQUIRE(row_before >= 0);
  REQUIRE(row_after >= 0);
  CHECK(row_before < 24);        // above the optical axis at first
  CHECK(row_after > row_before + 5);  // then lower in the picture (rows grow downwards)
}

TEST_CASE("render: drawing frames and camera images does not change the simulation", "[render][determinism]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  auto run = [](const std::string& engine, bool cameras) {
    const fs::path frames = fs::current_path() / "frames";
    fs::remove_all(frames);
    std::string xml = "<render engine=\"" + engine + "\" rate_hz=\"25\">";
    if (cameras) xml += "<camera name=\"top\" xyz=\"0 -8 6\" frames=\"" + frames.string() + "\"/>";
    xml += R"(</render><ground/>
      <type name="post" file="camera_post.xml"/><type name="ball" file="yellow_ball.xml"/>
      <type name="quad" file=")" + std::string(SSX_EXAMPLES_DIR) + R"(/artifacts/mk_quad.xml"/>
      <swarm type="quad" count="6" name="q{i}" spacing="1.5"/>)";
    if (cameras) xml += R"(<artifact name="eye" type="post" xyz="-3 0 1"/>)";
    xml += R"(<artifact name="ball" type="ball" xyz="2 3 2"/>)";
    Scene s = load(xml);
    s.environment->step(300);
    return s.environment->stateHash();
  };
  const std::uint64_t plain = run("null", false);
  CHECK(run("osmesa", true) == plain);
  CHECK(run("osmesa", false) == plain);
}

TEST_CASE("render: scene cameras write numbered PNG frames at their rate and a snapshot at the end", "[render]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  const fs::path dir = fs::current_path() / "render";
  fs::remove_all(dir);
  Scene s = load(R"(<render engine="osmesa" rate_hz="10" width="160" height="120">
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

TEST_CASE("render: a camera sensor without a drawing engine fails at start and says what to do", "[render]") {
  Scene s = load(R"(<type name="post" file="camera_post.xml"/><artifact name="eye" type="post"/>)");
  CHECK_THROWS_WITH(s.environment->start(), Catch::Contains("engine=\"osmesa\""));
}

TEST_CASE("render: a video path is only a file name: ffmpeg gets it as one argument, never through a shell",
          "[render][video]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  // a stand-in ffmpeg first on PATH: copies its input to the file named by its last argument
  const fs::path bin = fs::current_path() / "bin";
  fs::create_directories(bin);
  std::ofstream(bin / "ffmpeg") << "#!/bin/sh\nfor a in \"$@\"; do last=\"$a\"; done\ncat > \"${last#file:}\"\n";
  fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
  const char* path = std::getenv("PATH");
  REQUIRE(setenv("PATH", (bin.string() + ":" + (path != nullptr ? path : "/usr/bin:/bin")).c_str(), 1) == 0);
  // a shell would run "touch pwned" (the quote ends the quoted name); an argument vector does not
  const fs::path video = fs::current_path() / "clip'; touch pwned; echo '.mp4";
  Scene s = load(R"(<render engine="osmesa" rate_hz="10" width="64" height="48">
      <camera name="side" xyz="0 -6 2" look_at="0 0 1" video=")" + video.string() + R"("/>
    </render><ground/>
    <type name="ball" file="yellow_ball.xml"/><artifact name="ball" type="ball" xyz="0 0 2"/>)");
  s.environment->step(250);  // frames at steps 0, 50, ..., 200
  s.environment->stop();
  REQUIRE(fs::exists(video));
  CHECK(fs::file_size(video) == 5u * 64 * 48 * 3);
  CHECK_FALSE(fs::exists("pwned"));
  CHECK_FALSE(fs::exists(video.string() + ".ffmpeg.log"));  // removed after ffmpeg succeeded
}

TEST_CASE("render: an ffmpeg that fails makes stopping fail with the video's name", "[render][video]") {
  REQUIRE(haveOsmesa());
  const fs::path bin = fs::current_path() / "bin";
  fs::create_directories(bin);
  std::ofstream(bin / "ffmpeg") << "#!/bin/sh\necho 'no encoder here' >&2\nexit 1\n";
  fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
  const char* path = std::getenv("PATH");
  REQUIRE(setenv("PATH", (bin.string() + ":" + (path != nullptr ? path : "/usr/bin:/bin")).c_str(), 1) == 0);
  Scene s = load(R"(<render engine="osmesa" rate_hz="10" width="64" height="48">
      <camera name="side" xyz="0 -6 2" look_at="0 0 1" video="out.mp4"/>
    </render><ground/>
    <type name="ball" file="yellow_ball.xml"/><artifact name="ball" type="ball" xyz="0 0 2"/>)");
  // the dead pipe is found by a frame write (EPIPE, no SIGPIPE) or by ffmpeg's exit status
  bool reported = false;
  try {
    s.environment->step(250);
  } catch (const StepError& e) {
    CHECK_THAT(e.what(), Catch::Contains("out.mp4"));
    reported = true;
  }
  try {
    s.environment->stop();
  } catch (const Error& e) {
    CHECK_THAT(e.what(), Catch::Contains("ffmpeg") && Catch::Contains("out.mp4"));
    reported = true;
  }
  CHECK(reported);
  CHECK_THAT(slurpText("out.mp4.ffmpeg.log"), Catch::Contains("no encoder here"));
}

TEST_CASE("render: levels of detail keep a primitive's size in the image, and what is partly in view is drawn",
          "[render]") {
  REQUIRE(haveOsmesa());
  auto engine = osmesaEngine();
  CameraView view;  // at the origin, looking along +x, 640 x 480, 60 degrees
  view.far = 500;
  const double pixels_per_metre = 480 / (2 * std::tan(std::numbers::pi / 6) * 480 / 640);  // at 1 m
  Image im;
  // a thin disc (a rotor) and a sphere facing the camera, near (full detail) to far (the coarsest
  // polygon, a disc drawn as its face): the red area stays the true one
  RenderNodeSpec disc;
  disc.primitive = RenderNodeSpec::Primitive::Cylinder;
  disc.radius = 0.5;
  disc.length = 0.005;
  disc.color = {1, 0, 0, 1};
  RenderNodeSpec ball = disc;
  ball.primitive = RenderNodeSpec::Primitive::Sphere;
  const Quat facing(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()));  // the disc's axis along x
  for (const RenderNodeSpec* spec : {&disc, &ball})
    for (double d : {8.0, 30.0, 60.0, 100.0}) {
      const double r = 0.5 / d * pixels_per_metre;
      engine->renderView(view, {RenderNode{spec, nullptr, Pose{Vec3(d, 0, 0), facing}}}, {0.2f, 0.4f, 0.6f, 1}, im);
      const double area = std::numbers::pi * r * r;
      INFO((spec == &disc ? "disc" : "sphere") << " at " << d << " m: radius " << r << " px, "
                                               << redPixels(im).count << " red pixels for " << area);
      CHECK(redPixels(im).count == Approx(area).epsilon(r > 5 ? 0.05 : 0.15));
    }
  // a box mostly left of the image is still drawn at the image's left edge
  RenderNodeSpec box = disc;
  box.primitive = RenderNodeSpec::Primitive::Box;
  box.size = Vec3(1, 1, 1);
  const double edge = 10 * std::tan(std::numbers::pi / 6);  // the image's left edge at 10 m
  engine->renderView(view, {RenderNode{&box, nullptr, Pose{Vec3(10, edge + 0.4, 0), Quat::Identity()}}},
                     {0.2f, 0.4f, 0.6f, 1}, im);
  CHECK(redPixels(im, 0).count > 10);
  // one far beyond the far plane, or behind the camera, is not
  for (const Vec3& at : {Vec3(600, 0, 0), Vec3(-5, 0, 0)}) {
    engine->renderView(view, {RenderNode{&box, nullptr, Pose{at, Quat::Identity()}}}, {0.2f, 0.4f, 0.6f, 1}, im);
    CHECK(redPixels(im).count == 0);
  }
}

TEST_CASE("render: what appears small (placed and lit per vertex) has the colour it has up close (lit per pixel)",
          "[render]") {
  REQUIRE(haveOsmesa());
  auto engine = osmesaEngine();
  CameraView view;  // at the origin, looking along +x
  view.far = 500;
  // a unit box showing the camera its -x face, and a thin disc (a rotor) seen face on from either
  // side: lit by the eye light (0.3 + 0.3) and not the sun, which is behind them, at every distance
  RenderNodeSpec box;
  box.primitive = RenderNodeSpec::Primitive::Box;
  box.size = Vec3(1, 1, 1);
  box.color = {1, 0, 0, 1};
  RenderNodeSpec disc = box;
  disc.primitive = RenderNodeSpec::Primitive::Cylinder;
  disc.radius = 0.5;
  disc.length = 0.005;
  const Quat towards(Eigen::AngleAxisd(-std::numbers::pi / 2, Vec3::UnitY())), away = towards.conjugate();
  Image im;
  for (double d : {8.0, 40.0, 70.0, 120.0}) {
    engine->renderView(view, {RenderNode{&box, nullptr, Pose{Vec3(d, 0, 0), Quat::Identity()}}}, {0.2f, 0.4f, 0.6f, 1},
                       im);
    INFO("box at " << d << " m");
    CHECK(redPixels(im).mean == Approx(0.6 * 255).margin(6));
    for (const Quat& facing : {towards, away}) {
      engine->renderView(view, {RenderNode{&disc, nullptr, Pose{Vec3(d, 0, 0), facing}}}, {0.2f, 0.4f, 0.6f, 1}, im);
      INFO("disc at " << d << " m, facing " << (&facing == &towards ? "the camera" : "away"));
      CHECK(redPixels(im).mean == Approx(0.6 * 255).margin(6));
    }
  }
}
