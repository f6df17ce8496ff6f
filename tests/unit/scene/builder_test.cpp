// The scene builder: the world made from the model alone, its problems in document order.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>

using namespace ssx;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

// a scene with obstacles of every shape, its artifact file beside it, in a directory of its own
struct ObstacleScene {
  fs::path dir;
  fs::path scene;
  ObstacleScene() {
    char pattern[] = "/tmp/ssx_builder_XXXXXX";
    dir = ::mkdtemp(pattern);
    fs::copy_file(test::kArtifacts / "box.xml", dir / "box.xml");
    scene = dir / "scene.xml";
    std::ofstream(scene) << R"(<scene>
  <environment seed="5"/>
  <type name="box" file="box.xml"/>
  <ground/>
  <obstacle name="post" xyz="1 0 0.5" rpy="0 0 0.3" color="0.1 0.2 0.3">
    <cylinder radius="0.2" length="1"/>
    <box size="0.5 0.5 0.1" xyz="0 0 0.55" rpy="0.1 0 0" density="300"/>
  </obstacle>
  <obstacle name="round" xyz="-1 0 0.4"><sphere radius="0.4"/><capsule radius="0.1" xyz="0 0 1"/></obstacle>
  <swarm type="box" count="4" name="b{i}" layout="grid" spacing="0.8" xyz="0 2 1"/>
</scene>
)";
  }
  ~ObstacleScene() { fs::remove_all(dir); }
};

}  // namespace

TEST_CASE("the builder makes the world from the model alone: the files may be gone", "[scene][builder]") {
  ObstacleScene files;
  const SceneModel model = parseScene(files.scene, testOptions());
  Scene loaded = loadScene(files.scene, testOptions());
  fs::remove_all(files.dir);  // nothing of the scene is left to read
  REQUIRE_FALSE(fs::exists(files.scene));
  Scene built = buildScene(model, testOptions());
  REQUIRE(built.environment->artifactCount() == loaded.environment->artifactCount());
  built.environment->step(200);
  loaded.environment->step(200);
  CHECK(built.environment->stateHash() == loaded.environment->stateHash());
}

TEST_CASE("an obstacle's shapes are parsed into the model and built as written", "[scene][builder]") {
  ObstacleScene files;
  const SceneModel model = parseScene(files.scene, testOptions());
  const PlacementModel* post = nullptr;
  for (const PlacementModel& p : model.placements)
    if (p.kind == PlacementModel::Kind::Obstacle && p.name == "post") post = &p;
  REQUIRE(post != nullptr);
  REQUIRE(post->shapes.size() == 2);
  CHECK(post->shapes[0].shape.kind == Shape::Kind::Cylinder);
  CHECK(post->shapes[1].shape.density == 300);
  CHECK(post->shapes[1].rpy.x() == 0.1);
  CHECK(post->shapes[1].where.line == 7);
  CHECK(post->color[2] == 0.3f);

  Scene scene = buildScene(model, testOptions());
  const Artifact& a = *scene.environment->findArtifact("post");
  const PhysicNodeSpec& spec = a.root().spec();
  CHECK(spec.is_static);
  REQUIRE(spec.shapes.size() == 2);
  CHECK(spec.shapes[1].size.isApprox(Vec3(0.5, 0.5, 0.1)));
  CHECK(spec.shapes[1].pose.position.isApprox(Vec3(0, 0, 0.55)));
  CHECK(a.placement().position.isApprox(Vec3(1, 0, 0.5)));
  // what is drawn is what collides: same geometry, same pose, in the obstacle's colour
  const RenderNodeSpec& look = *a.renderRoots().at(0);
  REQUIRE(look.children.size() == 2);
  CHECK(look.children[0].primitive == RenderNodeSpec::Primitive::Cylinder);
  CHECK(look.children[0].length == 1.0);
  CHECK(look.children[1].pose.orientation.isApprox(spec.shapes[1].pose.orientation));
  CHECK(look.children[1].color[0] == 0.1f);
  // a capsule written without length is a sphere-ended zero-length capsule in both
  const Artifact& round = *scene.environment->findArtifact("round");
  CHECK(round.root().spec().shapes[1].length == 0);
  CHECK(round.renderRoots().at(0)->children[1].length == 0);
}

TEST_CASE("an obstacle changed in the model is built changed, and prints as it is", "[scene][builder]") {
  ObstacleScene files;
  SceneModel model = parseScene(files.scene, testOptions());
  for (PlacementModel& p : model.placements)
    if (p.name == "post") p.shapes[0].shape.radius = 0.35;
  const std::string xml = model.toXml();
  CHECK_THAT(xml, Contains(R"(<cylinder radius="0.35" length="1" xyz="0 0 0" rpy="0 0 0" density="1000"/>)"));
  CHECK_THAT(xml, Contains(R"(<box size="0.5 0.5 0.1" xyz="0 0 0.55" rpy="0.1 0 0" density="300"/>)"));
  Scene scene = buildScene(model, testOptions());
  CHECK(scene.environment->findArtifact("post")->root().spec().shapes[0].radius == 0.35);
  // and the printed model reads back to the same model
  CHECK(parseSceneString(xml, "printed.xml", files.dir, testOptions()) == model);
}

TEST_CASE("a model made in code with a bad value is reported by the builder, at the value's line", "[scene][builder]") {
  ObstacleScene files;
  SceneModel model = parseScene(files.scene, testOptions());
  model.placements.push_back(model.placements.at(1));  // the first obstacle again: its name is taken
  model.placements.back().where = {"code.xml", 40};
  try {
    (void)buildScene(model, testOptions());
    FAIL("built");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Contains("code.xml:40: error: duplicate artifact name 'post'"));
  }
}

TEST_CASE("robots that start inside one another are checked only when the reader found no errors", "[scene][builder]") {
  const std::string overlapping = R"(<scene>
    <type name="box" file="box.xml"/>
    <artifact name="a" type="box" xyz="0 0 1"/>
    <artifact name="b" type="box" xyz="0 0 1"/>
  )";
  CHECK_THROWS_WITH(loadSceneFromString(overlapping + "</scene>", "m.xml", test::kArtifacts, testOptions()),
                    Contains("'b' starts"));
  // an obstacle the reader refused is not in the model: what overlaps it could not be told
  try {
    (void)loadSceneFromString(overlapping + R"(<obstacle name="o"/></scene>)", "m.xml", test::kArtifacts, testOptions());
    FAIL("loaded");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Contains("m.xml:5: error: <obstacle>: needs at least one shape"));
    CHECK_THAT(e.what(), !Contains("starts"));
  }
}
