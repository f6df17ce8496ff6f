// ground: the floor's colour under a robot's points, from the floor colour, a floor image laid
// over its area (nearest pixel, alpha over the floor colour) and the regions painted over them
// (later over earlier); grey levels with noise kept within [0, 1]; what is wrong with the regions,
// points or image is said before anything runs, at its parameter.
#include "scene_util.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

using namespace ssx;
using namespace ssx::test;
using Catch::Contains;

namespace {

Scene scene(const std::string& ground, const std::string& where = "0 0 0") {
  const std::string xml = R"(<scene><environment timestep="0.01"/>
    <type name="epuck" file=")" + (kArtifacts / "epuck.xml").string() + R"("/>
    <ground/>
    <artifact name="r" type="epuck" xyz=")" + where + R"(">)" + ground + R"(</artifact></scene>)";
  return loadSceneFromString(xml, "ground.xml", kArtifacts, testOptions());
}

const GroundMeasurement& reading(Environment& env) {
  const Artifact& a = *env.findArtifact("r");
  for (std::size_t i = 0; i < a.sensorCount(); ++i)
    if (const auto* m = dynamic_cast<const GroundMeasurement*>(&a.sensor(i).latest())) return *m;
  throw std::runtime_error("no ground sensor");
}

// a temporary directory, removed at the end
struct Dir {
  std::filesystem::path path;
  Dir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "ssx_ground_XXXXXX").string();
    REQUIRE(mkdtemp(pattern.data()) != nullptr);
    path = pattern;
  }
  ~Dir() { std::filesystem::remove_all(path); }
};

// a 4 x 2 image: top row red, green, blue, white; bottom row black, grey, yellow, cyan
void writeQuads(const std::filesystem::path& file) {
  Image image;
  image.width = 4;
  image.height = 2;
  image.rgb = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255,  //
               0, 0, 0, 128, 128, 128, 255, 255, 0, 0, 255, 255};
  writePng(file, image);
}

}  // namespace

TEST_CASE("ground: each point reads the colour painted last under it, or the floor's", "[ground]") {
  // a red disc, a black rectangle over part of it; points ahead of and behind the robot (facing +x)
  Scene s = scene(R"(<sensor index="2" points="0.03 0; -0.03 0; 0 0.5" floor="1 1 1"
                       regions="circle 0.1 0 0.1 1 0 0; rect -0.2 -0.2 0.02 0.2 0 0 0"/>)");
  Environment& env = *s.environment;
  env.step();
  const GroundMeasurement& m = reading(env);
  REQUIRE(m.readings.size() == 3);
  CHECK(m.colors[0] == Vec3(1, 0, 0));  // at x 0.03: in the disc, not the rectangle
  CHECK(m.readings[0] == Approx(0.299));
  CHECK(m.colors[1] == Vec3(0, 0, 0));  // at x -0.03: the rectangle, painted over the disc
  CHECK(m.readings[1] == 0.0);
  CHECK(m.colors[2] == Vec3(1, 1, 1));  // at y 0.5: the floor
  CHECK(m.readings[2] == Approx(1.0));
}

TEST_CASE("ground: the points move with the robot, noise stays within [0, 1]", "[ground]") {
  Scene s = scene(R"(<sensor index="2" points="0.03 0" regions="rect 0.5 -1 2 1 0.5 0.5 0.5" noise="0.2"/>)",
                  "0.48 0 0");
  Environment& env = *s.environment;
  double sum = 0, lo = 1, hi = 0;
  for (int i = 0; i < 1000; ++i) {
    env.step();
    const double r = reading(env).readings[0];  // its front point at x 0.51: grey 0.5
    sum += r;
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  CHECK(sum / 1000 == Approx(0.5).margin(0.02));
  CHECK(lo >= 0.0);
  CHECK(hi <= 1.0);
  CHECK(hi - lo > 0.8);
}

TEST_CASE("ground: regions and points that are not right are refused at their parameter", "[ground]") {
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" regions="square 0 0 1 1 1 1"/>)"), Contains("a region is 'circle"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" regions="circle 0 0 1 1 1"/>)"), Contains("needs 6 numbers"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" regions="circle 0 0 1 2 0 0"/>)"), Contains("colours are within 0..1"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" points="0.1"/>)"), Contains("a point is 'X Y'"));
}

TEST_CASE("ground: a floor image laid over its area, the top row north, regions over it, the floor around it", "[ground]") {
  Dir dir;
  writeQuads(dir.path / "floor.png");
  // over x -1..1, y -0.5..0.5: each pixel 0.5 m square; the robot at the origin facing +x
  Scene s = scene(R"(<sensor index="2" points="-0.8 0.3; -0.3 0.3; 0.3 0.3; 0.8 0.3; -0.8 -0.3; 0.3 -0.3; 0.8 -0.3; 0 2; 0.9 -0.4"
                       floor="0.2 0.2 0.2" image=")" + (dir.path / "floor.png").string() +
                  R"(" image_area="-1 -0.5 1 0.5" regions="rect 0.85 -0.45 0.95 -0.35 1 0 1"/>)");
  Environment& env = *s.environment;
  env.step();
  const GroundMeasurement& m = reading(env);
  REQUIRE(m.colors.size() == 9);
  CHECK(m.colors[0] == Vec3(1, 0, 0));
  CHECK(m.colors[1] == Vec3(0, 1, 0));
  CHECK(m.colors[2] == Vec3(0, 0, 1));
  CHECK(m.colors[3] == Vec3(1, 1, 1));
  CHECK(m.colors[4] == Vec3(0, 0, 0));
  CHECK(m.colors[5] == Vec3(1, 1, 0));
  CHECK(m.colors[6] == Vec3(0, 1, 1));
  CHECK(m.colors[7] == Vec3(0.2, 0.2, 0.2));  // outside the area: the floor
  CHECK(m.colors[8] == Vec3(1, 0, 1));        // a region painted over the image
  CHECK(m.readings[2] == Approx(0.114));
  // a turn of half a circle: the points move with the robot (the first now reads the cyan corner)
  Artifact& r = *env.findArtifact("r");
  BodyState state = r.root().state();
  state.pose.orientation = Quat(Eigen::AngleAxisd(3.141592653589793, Vec3::UnitZ()));
  env.setBodyState(r.root().bodyIndex(), state);
  env.step();
  CHECK(reading(env).colors[0] == Vec3(0, 1, 1));
}

TEST_CASE("ground: a floor image's alpha mixes it with the floor colour, a relative path is the scene file's", "[ground]") {
  Dir dir;
  std::filesystem::copy_file(kData / "ground" / "alpha_2x2.png", dir.path / "alpha.png");
  // 2 x 2 pixels over 0..2 x 0..2: red opaque, green transparent (top); blue at alpha 128, black (bottom)
  std::ofstream(dir.path / "scene.xml") << R"(<scene><environment timestep="0.01"/>
    <type name="epuck" file=")" + (kArtifacts / "epuck.xml").string() + R"("/>
    <artifact name="r" type="epuck" xyz="0 0 0">
      <sensor index="2" points="0.5 1.5; 1.5 1.5; 0.5 0.5; 1.5 0.5" floor="1 1 1" image="alpha.png" image_area="0 0 2 2"/>
    </artifact></scene>)";
  Scene s = loadScene(dir.path / "scene.xml", testOptions());
  Environment& env = *s.environment;
  env.step();
  const GroundMeasurement& m = reading(env);
  CHECK(m.colors[0] == Vec3(1, 0, 0));
  CHECK(m.colors[1] == Vec3(1, 1, 1));  // transparent: the floor
  const double a = 128 / 255.0;
  CHECK(m.colors[2].x() == Approx(1 - a));
  CHECK(m.colors[2].z() == Approx(1.0));
  CHECK(m.colors[3] == Vec3(0, 0, 0));
}

TEST_CASE("ground: a floor image that cannot be read, or without its area, is refused at its parameter", "[ground]") {
  Dir dir;
  writeQuads(dir.path / "floor.png");
  const std::string png = (dir.path / "floor.png").string();
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" image="/nonexistent/floor.png" image_area="0 0 1 1"/>)"),
                    Contains("ground.xml:") && Contains("'/nonexistent/floor.png' is not a file"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" image=")" + (kArtifacts / "epuck.xml").string() + R"(" image_area="0 0 1 1"/>)"),
                    Contains("not a PNG image"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" image=")" + dir.path.string() + R"(" image_area="0 0 1 1"/>)"),
                    Contains("is not a file"));  // a directory
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" image=")" + png + R"("/>)"), Contains("image and image_area go together"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" image_area="0 0 1 1"/>)"), Contains("image and image_area go together"));
  CHECK_THROWS_WITH(scene(R"(<sensor index="2" image=")" + png + R"(" image_area="0 0 -1 1"/>)"),
                    Contains("'X0 Y0 X1 Y1' (m, world) with X1 > X0"));
}
