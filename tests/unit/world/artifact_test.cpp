// Artifacts: shared type trees, and node poses in the body that do not depend on the placement.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("a swarm's members share their type's physic and render trees: one copy whatever the count", "[scene]") {
  const std::string xml = R"(<scene>
    <type name="quad" file="mk_quad.xml"/>
    <swarm type="quad" count="3" name="q{i}" spacing="2"/>
    <artifact name="solo" type="quad" xyz="0 -5 0"/>
  </scene>)";
  Scene scene = loadSceneFromString(xml, "memory.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts", testOptions());
  Environment& env = *scene.environment;
  const Artifact& a = *env.findArtifact("q0");
  REQUIRE(a.renderRoots().size() >= 1);
  for (const char* name : {"q1", "q2", "solo"}) {
    const Artifact& b = *env.findArtifact(name);
    REQUIRE(b.renderRoots().size() == a.renderRoots().size());
    for (std::size_t i = 0; i < a.renderRoots().size(); ++i) CHECK(b.renderRoots()[i].get() == a.renderRoots()[i].get());
  }
  // a tree added by value is the artifact's own; a null tree is refused
  Artifact& extra = env.addArtifact("extra", Pose{});
  RenderNodeSpec ball;
  ball.primitive = RenderNodeSpec::Primitive::Sphere;
  extra.addRenderRoot(ball);
  REQUIRE(extra.renderRoots().size() == 1);
  CHECK(extra.renderRoots()[0]->primitive == RenderNodeSpec::Primitive::Sphere);
  CHECK_THROWS_WITH(extra.addRenderRoot(std::shared_ptr<const RenderNodeSpec>()), Catch::Contains("null render node tree"));
}

TEST_CASE("a node's pose in its body is its type's, to the bit, wherever the artifact was placed", "[scene]") {
  const std::string xml = R"(<scene>
    <type name="quad" file="mk_quad.xml"/>
    <artifact name="here" type="quad"/>
    <artifact name="there" type="quad" xyz="123.4 -56.7 8.9" rpy="0.3 0.2 1.1"/>
  </scene>)";
  Scene scene = loadSceneFromString(xml, "placed.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts", testOptions());
  Environment& env = *scene.environment;
  // known from loading on (a quadrotor's load-time checks read its rotors'), and the same after start
  const Vec3 loaded = env.findArtifact("there")->node("rotor1")->poseInBody().position;
  env.start();
  CHECK(env.findArtifact("there")->node("rotor1")->poseInBody().position == loaded);
  for (const char* node : {"rotor0", "rotor1", "rotor2", "rotor3"}) {
    const Pose& here = env.findArtifact("here")->node(node)->poseInBody();
    const Pose& there = env.findArtifact("there")->node(node)->poseInBody();
    INFO(node);
    CHECK(here.position == there.position);
    CHECK(here.orientation.coeffs() == there.orientation.coeffs());
  }
  // mk_quad's centre of mass is its root's origin: the rotors sit where the file puts them
  CHECK(env.findArtifact("there")->node("rotor1")->poseInBody().position == Vec3(0, 0.225, 0.02));
}
