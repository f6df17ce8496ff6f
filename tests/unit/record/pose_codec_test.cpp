// The compact pose message: positions as float32, orientations as int16 quaternions with w >= 0.
#include "record/pose_codec.hpp"

#include <ssx/ssx.hpp>

#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace ssx;
using ssx::test::boxBody;

TEST_CASE("pose codec: positions to the float, orientations to 1e-4, w made non-negative", "[record][poses]") {
  Environment env;
  const Quat turned(Eigen::AngleAxisd(2.5, Vec3(1, 2, 3).normalized()));
  const Quat flipped(-0.5, 0.5, -0.5, 0.5);  // w < 0: the same rotation as its negation
  std::vector<const PhysicNode*> nodes;
  int made = 0;
  for (const auto& [at, q] : {std::pair{Vec3(1.25, -3.5, 0.1), turned}, std::pair{Vec3(1e4, 2e-3, -7), flipped}}) {
    Artifact& a = env.addArtifact("b" + std::to_string(made++), Pose{at, q});
    a.addPhysicRoot(boxBody(Vec3(0.2, 0.2, 0.2), 1.0));
  }
  env.start();
  for (std::size_t i = 0; i < env.artifactCount(); ++i) nodes.push_back(&std::as_const(env).artifact(i).root());
  std::vector<std::byte> message;
  detail::encodePoses(nodes, message);
  CHECK(message.size() == 4 + 2 * (12 + 8));
  CHECK(detail::poseCount(message) == 2);
  std::vector<float> p, q;
  detail::decodePoses(message, &p, &q);
  REQUIRE(p.size() == 6);
  REQUIRE(q.size() == 8);
  for (std::size_t i = 0; i < 2; ++i) {
    const Pose truth = nodes[i]->pose();
    for (std::size_t k = 0; k < 3; ++k) CHECK(p[3 * i + k] == static_cast<float>(truth.position[static_cast<Eigen::Index>(k)]));
    Quat got(q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]);
    CHECK(got.w() >= 0);
    CHECK(got.angularDistance(truth.orientation) < 2e-4);
  }
  // a message whose size does not fit its count
  message.pop_back();
  CHECK_THROWS_WITH(detail::decodePoses(message, &p, &q), Catch::Contains("does not hold the 2 bodies it says"));
  CHECK(detail::poseCount(std::vector<std::byte>(3)) == 0);
}
