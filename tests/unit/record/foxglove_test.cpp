// Foxglove's well-known messages as JSON: transforms of the bodies, the shapes of the scene.
#include "record/foxglove.hpp"

#include <catch2/catch.hpp>

#include <charconv>
#include <string>
#include <vector>

using namespace ssx;
using namespace ssx::detail;

namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("foxglove: FrameTransforms, one transform from the world to each body", "[record][foxglove]") {
  const std::vector<std::string> names{"q0", "q1"};
  const std::vector<float> p{1, 2, 3, -1, 0.5f, 0};
  const std::vector<float> q{1, 0, 0, 0, 0, 0, 0, 1};  // w x y z
  const std::string json = frameTransforms(1'500'000'000, names, p, q);
  CHECK(json ==
        R"({"transforms":[{"timestamp":{"sec":1,"nsec":500000000},"parent_frame_id":"world","child_frame_id":"q0",)"
        R"("translation":{"x":1,"y":2,"z":3},"rotation":{"x":0,"y":0,"z":0,"w":1}},)"
        R"({"timestamp":{"sec":1,"nsec":500000000},"parent_frame_id":"world","child_frame_id":"q1",)"
        R"("translation":{"x":-1,"y":0.5,"z":0},"rotation":{"x":0,"y":0,"z":1,"w":0}}]})");
}

TEST_CASE("foxglove: SceneUpdate, an entity per frame locked to it, each primitive as Foxglove draws it",
          "[record][foxglove]") {
  using P = RenderNodeSpec::Primitive;
  RenderNodeSpec box, sphere, capsule, plane, frame_only;
  box.primitive = P::Box;
  box.size = Vec3(0.2, 0.3, 0.4);
  sphere.primitive = P::Sphere;
  sphere.radius = 0.05;
  capsule.primitive = P::Capsule;
  capsule.radius = 0.1;
  capsule.length = 2;
  plane.primitive = P::Plane;
  plane.size = Vec3(50, 50, 1);
  frame_only.primitive = P::None;
  const std::vector<SceneShape> shapes{{"q1", &box, Pose{}},        {"q1", &sphere, Pose{Vec3(0, 0, 1), Quat::Identity()}},
                                       {"q0", &capsule, Pose{}},    {"world", &plane, Pose{}},
                                       {"q0", &frame_only, Pose{}}};
  const std::string json = sceneUpdate(0, shapes);
  // three entities, in name order, every one locked to its frame and kept until replaced
  CHECK(count(json, R"("frame_locked":true)") == 3);
  CHECK(count(json, R"("lifetime":{"sec":0,"nsec":0})") == 3);
  const auto q0 = json.find(R"("frame_id":"q0")"), q1 = json.find(R"("frame_id":"q1")"),
             world = json.find(R"("frame_id":"world")");
  REQUIRE(q0 != std::string::npos);
  REQUIRE(q1 != std::string::npos);
  REQUIRE(world != std::string::npos);
  CHECK(q0 < q1);
  CHECK(q1 < world);
  // the box as a cube of its edges; the sphere by its diameter
  CHECK(json.find(R"("size":{"x":0.2,"y":0.3,"z":0.4})") != std::string::npos);
  CHECK(json.find(R"("position":{"x":0,"y":0,"z":1},"orientation":{"x":0,"y":0,"z":0,"w":1}},"size":{"x":0.1,"y":0.1,"z":0.1})") !=
        std::string::npos);
  // the capsule: a cylinder of its straight part and a sphere at each end
  CHECK(count(json, R"("bottom_scale":1,"top_scale":1)") == 1);
  CHECK(json.find(R"("size":{"x":0.2,"y":0.2,"z":2})") != std::string::npos);
  CHECK(json.find(R"("position":{"x":0,"y":0,"z":-1})") != std::string::npos);
  CHECK(json.find(R"("position":{"x":0,"y":0,"z":1},"orientation":{"x":0,"y":0,"z":0,"w":1}},"size":{"x":0.2)") !=
        std::string::npos);
  // the plane: a thin slab just below it
  CHECK(json.find(R"("position":{"x":0,"y":0,"z":-5e-04})") != std::string::npos);
  CHECK(json.find(R"("size":{"x":50,"y":50,"z":0.001})") != std::string::npos);
  // brackets balance (the JSON itself is parsed by the independent reader's test)
  CHECK(count(json, "{") == count(json, "}"));
  CHECK(count(json, "[") == count(json, "]"));
}
