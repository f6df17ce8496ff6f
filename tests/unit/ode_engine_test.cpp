// Physics checks of the ODE backend through the public API (spec section 7, no rotors).
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace ssx;
using ssx::test::at;

namespace {

EnvironmentSettings zeroGravity(double dt) {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(dt);
  s.threads = 1;
  s.physics.gravity = Vec3::Zero();
  return s;
}

// a free rigid body with the given principal inertia, spinning at w_body
Artifact& spinningBody(Environment& env, const Vec3& inertia, const Vec3& w_body) {
  Mat3 j = inertia.asDiagonal();
  Artifact& a = env.addArtifact("top", at(0, 0, 0));
  a.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0, &j));
  a.root().setVelocity(Vec3::Zero(), w_body);  // body axes = world axes at start
  return a;
}

Vec3 bodyRate(const Artifact& a) {
  const BodyState s = a.state();
  return s.pose.orientation.conjugate() * s.angular_velocity;
}

}  // namespace

TEST_CASE("free fall matches the closed form of semi-implicit Euler", "[physics]") {
  // ODE integrates v += g h, then x += v h: after n steps z = z0 - g h^2 n (n + 1) / 2,
  // which is the exact parabola plus an O(h) offset of -g t h / 2
  const double h = 0.001;
  EnvironmentSettings s;
  s.timestep = toNanoseconds(h);
  s.threads = 1;
  Environment env(s);
  Artifact& a = env.addArtifact("ball", at(0, 0, 100));
  a.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
  const int n = 1000;
  env.step(n);
  const double g = 9.81;
  const double expected = 100.0 - g * h * h * n * (n + 1) / 2.0;
  CHECK(a.pose().position.z() == Approx(expected).margin(1e-9));
  CHECK(a.state().linear_velocity.z() == Approx(-g * n * h).margin(1e-9));
  // the exact parabola differs by g t h / 2
  const double exact = 100.0 - 0.5 * g * 1.0 * 1.0;
  CHECK(std::abs(a.pose().position.z() - exact) == Approx(0.5 * g * 1.0 * h).margin(1e-9));
  // acceleration from the snapshot is gravity
  CHECK(a.state().linear_acceleration.isApprox(Vec3(0, 0, -g), 1e-9));
}

TEST_CASE("torque-free symmetric top precesses at (J3 - J1)/J1 w3", "[physics]") {
  Environment env(zeroGravity(0.001));
  const Vec3 j(0.009, 0.009, 0.018);
  Artifact& a = spinningBody(env, j, Vec3(0.5, 0, 10));
  const double e0 = 0.5 * bodyRate(a).dot(j.cwiseProduct(bodyRate(a)));
  const Vec3 l0 = a.state().pose.orientation * j.cwiseProduct(bodyRate(a));

  // unwrap the angle of the transverse body rate over 2 s
  double angle = 0, last = std::atan2(bodyRate(a).y(), bodyRate(a).x());
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    env.step();
    const Vec3 w = bodyRate(a);
    const double now = std::atan2(w.y(), w.x());
    double d = now - last;
    if (d > std::numbers::pi) d -= 2 * std::numbers::pi;
    if (d < -std::numbers::pi) d += 2 * std::numbers::pi;
    angle += d;
    last = now;
  }
  const double rate = angle / (n * 0.001);
  // Euler's equations: w1' = -(J3 - J1)/J1 w3 w2, w2' = (J3 - J1)/J1 w3 w1, so the body-frame
  // transverse rate turns counter-clockwise at (J3 - J1)/J1 w3 = 10 rad/s
  CHECK(rate == Approx(10.0).epsilon(0.01));

  const Vec3 w = bodyRate(a);
  const double e = 0.5 * w.dot(j.cwiseProduct(w));
  const Vec3 l = a.state().pose.orientation * j.cwiseProduct(w);
  INFO("energy drift " << (e - e0) / e0 << ", momentum drift " << (l - l0).norm() / l0.norm());
  CHECK(std::abs(e - e0) / e0 < 1e-3);
  CHECK((l - l0).norm() / l0.norm() < 1e-3);
  // the figures the README gives, to their last digit
  CHECK((e - e0) / e0 == Approx(-1.9e-4).margin(0.05e-4));
  CHECK((l - l0).norm() / l0.norm() == Approx(1.1e-4).margin(0.05e-4));
}

TEST_CASE("spin about the intermediate axis flips (Dzhanibekov)", "[physics]") {
  Environment env(zeroGravity(0.001));
  const Vec3 j = Vec3(1, 2, 3) * 1e-2;
  Artifact& a = spinningBody(env, j, Vec3(0.01, 5.0, 0.01));
  double min_wy = 5.0;
  double first_flip_s = -1;
  for (int i = 0; i < 10000; ++i) {
    env.step();
    const double wy = bodyRate(a).y();
    min_wy = std::min(min_wy, wy);
    if (first_flip_s < 0 && wy < 0) first_flip_s = (i + 1) * 0.001;
  }
  INFO("first sign change of the body y rate at " << first_flip_s << " s");
  CHECK(first_flip_s > 0);
  CHECK(first_flip_s == Approx(2.7).margin(0.05));  // the README's figure
  // a full flip: the body y rate reverses to nearly its full magnitude
  CHECK(min_wy < -4.5);
}

TEST_CASE("a box resting on the ground stays put", "[physics]") {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.001);
  s.threads = 1;
  Environment env(s);
  env.addGround();
  Artifact& box = env.addArtifact("box", at(0.3, -0.2, 0.1));
  box.addPhysicRoot(test::boxBody(Vec3(0.2, 0.2, 0.2), 1.0));
  env.step(2000);
  const Pose p = box.pose();
  CHECK((p.position.head<2>() - Vec3(0.3, -0.2, 0).head<2>()).norm() < 1e-4);
  CHECK(p.position.z() == Approx(0.1).margin(2e-3));  // within the contact surface layer
  CHECK(p.orientation.angularDistance(Quat::Identity()) < 1e-3);
  CHECK(box.state().linear_velocity.norm() < 1e-3);
}

TEST_CASE("a force off the centre of mass also turns the body", "[physics]") {
  Environment env(zeroGravity(0.001));
  Artifact& a = env.addArtifact("bar", at(0, 0, 0));
  a.addPhysicRoot(test::boxBody(Vec3(1.0, 0.1, 0.1), 1.0));
  a.setDriver(std::make_unique<test::LambdaDriver>([](Driver& d, const StepInfo& info) {
    if (info.step == 0) d.artifact().root().addForce(Vec3(0, 1, 0), Frame::World, Vec3(0.5, 0, 0), Frame::Local);
  }));
  env.step(3);
  // the driver's force of step 0 is held until its next run (step 1), so it acts for 1 ms in step 1
  const BodyState s = a.state();
  CHECK(s.linear_velocity.y() == Approx(0.001).margin(1e-12));
  // torque 0.5 N m about z, Izz = (1 + 0.01) / 12
  CHECK(s.angular_velocity.z() == Approx(0.5 * 0.001 / ((1.0 + 0.01) / 12.0)).epsilon(1e-9));
}

TEST_CASE("node frames offset from the centre of mass are tracked", "[physics]") {
  Environment env(zeroGravity(0.001));
  PhysicNodeSpec root;
  root.name = "hub";
  root.shapes.push_back(Shape::sphere(0.05));
  root.mass = 1.0;
  PhysicNodeSpec arm;
  arm.name = "tip";
  arm.pose.position = Vec3(1, 0, 0);
  arm.mass = 1.0;
  arm.inertia = Mat3::Identity() * 1e-3;
  root.addChild(arm);
  Artifact& a = env.addArtifact("dumbbell", at(0, 0, 0));
  a.addPhysicRoot(root);
  a.root().setVelocity(Vec3::Zero(), Vec3(0, 0, 1));  // spin about the hub's origin
  env.step();
  // the hub origin is 0.5 m from the centre of mass; both nodes keep 1 m apart and turn together
  const Pose hub = a.node("hub")->pose();
  const Pose tip = a.node("tip")->pose();
  CHECK((tip.position - hub.position).norm() == Approx(1.0).epsilon(1e-9));
  CHECK(hub.orientation.angularDistance(tip.orientation) < 1e-12);
  // the hub was given zero linear velocity at its origin, so the centre moves at w x r
  const Vec3 com = (hub.position + tip.position) / 2;
  CHECK(a.node("hub")->state().linear_velocity.norm() == Approx(0.0).margin(1e-3));
  CHECK((com - Vec3(0.5, 0.5 * 0.001, 0)).norm() < 1e-6);
}
