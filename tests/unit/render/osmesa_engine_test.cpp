// The osmesa engine: pixel facts on known scenes, levels of detail and lighting.
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

TEST_CASE("render: an empty scene is all background", "[render]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  Scene s = loadRenderScene(R"(<render engine="osmesa" background="0.2 0.4 0.6"/>
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

namespace {

// pixels of `shaded` darker than the same pixel of `plain` (by more than 6 in the sum of its
// channels), the mean darkening, and their mean row; and how many pixels are brighter instead
struct Darker {
  int count = 0, brighter = 0;
  double mean = 0, row = -1;
};
Darker darker(const Image& plain, const Image& shaded) {
  Darker d;
  double sum = 0, rows = 0;
  for (int y = 0; y < plain.height; ++y)
    for (int x = 0; x < plain.width; ++x) {
      const std::uint8_t *a = plain.pixel(x, y), *b = shaded.pixel(x, y);
      const int drop = (a[0] + a[1] + a[2]) - (b[0] + b[1] + b[2]);
      if (drop > 6) {
        ++d.count;
        sum += drop;
        rows += y;
      } else if (drop < -3) {
        ++d.brighter;
      }
    }
  if (d.count > 0) {
    d.mean = sum / d.count;
    d.row = rows / d.count;
  }
  return d;
}

}  // namespace

TEST_CASE("render: a robot casts a shadow on the ground below it, fainter the higher it flies, without ground none",
          "[render][shadows]") {
  REQUIRE(haveOsmesa());
  auto engine = osmesaEngine();
  for (bool ground : {true, false}) {
    Scene s = loadRenderScene(std::string(ground ? "<ground/>" : "") + R"(<render engine="osmesa"/>
      <type name="post" file="camera_post.xml"/><artifact name="eye" type="post" xyz="0 0 1"/>
      <type name="ball" file="yellow_ball.xml"/><artifact name="ball" type="ball" xyz="6 0 1.5"/>)");
    Environment& env = *s.environment;
    env.step();  // the camera sensor poses the render nodes
    CameraView view;  // from above and behind, looking down at the ball
    view.pose = Pose{Vec3(0, 0, 5), Quat(Eigen::AngleAxisd(0.6, Vec3::UnitY()))};
    Image plain, shaded;
    engine->renderView(view, env.renderNodes(), {0.2f, 0.4f, 0.6f, 1}, plain);
    view.shadows = true;
    engine->renderView(view, env.renderNodes(), {0.2f, 0.4f, 0.6f, 1}, shaded);
    const Darker low = darker(plain, shaded);
    INFO("ground " << ground << ": " << low.count << " pixels darker by " << low.mean << " on average");
    CHECK(low.brighter == 0);
    if (!ground) {
      CHECK(low.count == 0);
      continue;
    }
    CHECK(low.count > 100);
    CHECK(low.row > yellowRow(plain));  // below the ball in the picture: on the ground
    CHECK(yellowRow(shaded) == Approx(yellowRow(plain)).margin(0.5));  // the ball itself is as it was
    // the same ball 3 m higher: a fainter shadow in the same place on the ground
    const int body = env.findArtifact("ball")->root().bodyIndex();
    BodyState high = env.bodyState(body);
    high.pose.position.z() += 3;
    env.setBodyState(body, high);
    env.step();
    engine->renderView(view, env.renderNodes(), {0.2f, 0.4f, 0.6f, 1}, shaded);
    view.shadows = false;
    engine->renderView(view, env.renderNodes(), {0.2f, 0.4f, 0.6f, 1}, plain);
    const Darker far = darker(plain, shaded);
    CHECK(far.count > 100);
    CHECK(far.mean < 0.8 * low.mean);
    CHECK(far.row == Approx(low.row).margin(3));
  }
}
