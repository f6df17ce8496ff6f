// The differential drive's model alone: hosted by a test driver that sets the wheels itself.
#include "drive_model.hpp"

#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

using namespace ssx;
using namespace ssx::ground;

namespace {

const std::filesystem::path kArtifacts = std::filesystem::path(SSX_EXAMPLES_DIR) / "artifacts";

// a 1 kg box at 0.1 m on the ground, driven by a swarm drive model: wheels of 2 cm on a 10 cm axle
struct Driven {
  Scene scene;
  DriveModel model;
  Random noise{7};
  Artifact* box = nullptr;
  explicit Driven(double v, double w, const std::string& noise_sd = "0") {
    scene = loadSceneFromString(
        "<scene><environment timestep=\"0.002\"/><ground/><type name=\"box\" file=\"box.xml\"/>"
        "<artifact name=\"b\" type=\"box\" xyz=\"0 0 0.1\"/></scene>",
        "drive.xml", kArtifacts);
    box = scene.environment->findArtifact("b");
    Descriptor params("driver");
    params.setDeclarations(kDriveModelParameters);
    params.set("wheel_radius", 0.02)
        .set("axle_length", 0.1)
        .set("max_wheel_speed", 10.0)
        .set("encoder_noise", noise_sd);
    box->setDriver(std::make_unique<test::LambdaDriver>([this, params, v, w](Driver& d, const StepInfo& info) {
      if (info.step == 0) model.configure(params, d.artifact());
      model.setTwist(v, w);
      model.apply(toSeconds(info.period));
      model.measure(toSeconds(info.period), noise);
    }));
  }
};

}  // namespace

TEST_CASE("the swarm model drives the body at the wheels' twist, on its plane, and its odometry follows",
          "[diff_drive][parts]") {
  Driven d(0.1, 0.5);               // 0.1 m/s on a circle of 0.2 m radius
  d.scene.environment->step(2000);  // 4 s
  const BodyState s = d.box->state();
  CHECK(s.linear_velocity.head<2>().norm() == Approx(0.1).margin(1e-3));
  CHECK(s.angular_velocity.z() == Approx(0.5).margin(1e-3));
  CHECK(s.pose.position.z() == Approx(0.1).margin(1e-3));  // held at its height (it floats over the ground)
  // dead-reckoned from the encoders: where it is, within a millimetre (no slip in this model)
  const Odometry& o = d.model.odometry();
  CHECK(std::hypot(o.x - s.pose.position.x(), o.y - s.pose.position.y()) < 1e-3);
  CHECK(std::abs(wrapAngle(o.yaw - yawOf(s.pose.orientation))) < 1e-3);
  CHECK(o.forward == Approx(0.1).margin(1e-3));
}

TEST_CASE("wheel speeds beyond the limit are scaled alike, keeping the curvature", "[diff_drive][parts]") {
  Driven d(1.0, 5.0);  // asks 37.5 and 62.5 rad/s of wheels that turn at most 10
  d.scene.environment->step(1);
  CHECK(d.model.right() == Approx(10));
  CHECK(d.model.left() == Approx(6));
}

TEST_CASE("encoder noise makes the odometry drift, and saves and restores with it", "[diff_drive][parts]") {
  Driven quiet(0.1, 0.0), noisy(0.1, 0.0, "0.5");
  quiet.scene.environment->step(1000);
  noisy.scene.environment->step(1000);
  // straight on: the two encoders agree without noise, and part with it
  CHECK(quiet.model.odometry().left_angle == Approx(quiet.model.odometry().right_angle).margin(1e-9));
  CHECK(std::abs(noisy.model.odometry().left_angle - noisy.model.odometry().right_angle) > 1e-3);
  std::vector<std::byte> bytes;
  StateWriter out(bytes);
  noisy.model.saveState(out);
  DriveModel copy;
  StateReader in(bytes);
  copy.loadState(in);
  CHECK(copy.odometry().x == noisy.model.odometry().x);
  CHECK(copy.odometry().yaw == noisy.model.odometry().yaw);
  CHECK(copy.left() == noisy.model.left());
}
