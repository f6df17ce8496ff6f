// The quadrotor model and controller: spec section 7 checks, fixed point against its float
// reference, IMU statistics, and closed-loop flight.
#include "fixed_point.hpp"
#include "quadrotor_model.hpp"
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

using namespace ssx;
using namespace ssx::quadrotor;
namespace fs = std::filesystem;

namespace {

std::vector<Rotor> plusRotors(double arm) {
  return {{Vec3(arm, 0, 0), 1}, {Vec3(0, arm, 0), -1}, {Vec3(-arm, 0, 0), 1}, {Vec3(0, -arm, 0), -1}};
}

// one mk_quad from examples/artifacts, with the scene's overrides for its driver and sensors

}  // namespace

TEST_CASE("rotor speeds for hover balance the weight within 1 %", "[quadrotor]") {
  // the mk_quad preset with its model mass; the rotors held at w_h = sqrt(m g / (4 kF))
  const RotorParams p = *preset("mk_quad");
  const double m = 0.82, g = 9.81;
  const double w_h = std::sqrt(m * g / (4 * p.thrust_coefficient));
  EnvironmentSettings s;
  s.timestep = toNanoseconds(0.002);
  Environment env(s);
  Mat3 j = Vec3(0.009, 0.009, 0.018).asDiagonal();
  Artifact& a = env.addArtifact("quad", test::at(0, 0, 5));
  a.addPhysicRoot(test::boxBody(Vec3(0.2, 0.2, 0.05), m, &j));
  auto model = std::make_shared<RotorModel>(plusRotors(0.225), p);
  model->setSpeeds(std::vector<double>(4, w_h));
  a.setDriver(std::make_unique<test::LambdaDriver>([model, w_h](Driver& d, const StepInfo&) {
    model->step(0.002, std::vector<double>(4, w_h));
    const BodyState st = d.artifact().state();
    Vec3 f, t;
    model->wrench(st.pose.orientation.conjugate() * st.linear_velocity, Vec3::Zero(), f, t);
    d.artifact().root().addForce(f, Frame::Local);
    d.artifact().root().addTorque(t, Frame::Local);
  }));
  env.step();  // the first step falls: the driver's forces act from the second step on
  const double v0 = a.state().linear_velocity.z();
  env.step(500);  // 1 s
  const BodyState st = a.state();
  CHECK(std::abs(st.linear_acceleration.z()) < 0.01 * g);
  CHECK(std::abs(st.linear_velocity.z() - v0) < 0.01 * g * 1.0);
  CHECK(st.angular_velocity.norm() < 1e-9);  // the reaction torques cancel
}

TEST_CASE("a motor step reaches 63.2 % at the up time constant", "[quadrotor]") {
  const RotorParams p = *preset("mk_quad");
  RotorModel model(plusRotors(0.225), p);
  const double dt = 1e-5;
  const auto steps = static_cast<int>(std::llround(p.time_constant_up / dt));
  for (int i = 0; i < steps; ++i) model.step(dt, std::vector<double>(4, 800.0));
  CHECK(model.speeds()[0] / 800.0 == Approx(1 - std::exp(-1.0)).margin(1e-9));
  // and down with the other constant
  const auto down = static_cast<int>(std::llround(p.time_constant_down / dt));
  const double from = model.speeds()[0];
  for (int i = 0; i < down; ++i) model.step(dt, std::vector<double>(4, 0.0));
  CHECK(model.speeds()[0] / from == Approx(std::exp(-1.0)).margin(1e-9));
}

TEST_CASE("a single counter-clockwise rotor yaws the body clockwise", "[quadrotor]") {
  EnvironmentSettings s;
  s.physics.gravity = Vec3::Zero();
  Environment env(s);
  Mat3 j = Vec3(0.009, 0.009, 0.018).asDiagonal();
  Artifact& a = env.addArtifact("quad", test::at(0, 0, 5));
  a.addPhysicRoot(test::boxBody(Vec3(0.2, 0.2, 0.05), 0.82, &j));
  // one CCW rotor at the centre: its reaction torque alone
  auto model = std::make_shared<RotorModel>(std::vector<Rotor>{{Vec3::Zero(), 1}}, *preset("mk_quad"));
  a.setDriver(std::make_unique<test::LambdaDriver>([model](Driver& d, const StepInfo&) {
    model->step(0.001, {500.0});
    Vec3 f, t;
    model->wrench(Vec3::Zero(), Vec3::Zero(), f, t);
    d.artifact().root().addTorque(t, Frame::Local);
  }));
  env.step(200);
  CHECK(a.state().angular_velocity.z() < -0.1);  // clockwise seen from above
  CHECK(std::abs(a.state().angular_velocity.x()) < 1e-9);
}

TEST_CASE("the allocation times its inverse is the identity", "[quadrotor]") {
  for (const char* name : {"mk_quad", "hummingbird", "crazyflie"}) {
    const RotorParams p = *preset(name);
    const Allocation al(plusRotors(0.17), p);
    CHECK((al.matrix() * al.inverse() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff() < 1e-9);
    // and the columns follow the spec: rotor on +y gives +tau_x, a CCW rotor gives -tau_z
    CHECK(al.matrix()(0, 1) > 0);
    CHECK(al.matrix()(2, 0) < 0);
  }
  // an X configuration with six rotors: still a right inverse
  std::vector<Rotor> hexa;
  for (int i = 0; i < 6; ++i) {
    const double ang = i * std::numbers::pi / 3;
    hexa.push_back({Vec3(0.3 * std::cos(ang), 0.3 * std::sin(ang), 0), i % 2 == 0 ? 1 : -1});
  }
  const Allocation al(hexa, *preset("mk_quad"));
  CHECK((al.matrix() * al.inverse() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("fixed-point helpers: rounding shift, square root, CORDIC", "[quadrotor][fixed]") {
  CHECK(fixed::roundShift(5, 1) == 3);
  CHECK(fixed::roundShift(-5, 1) == -2);
  CHECK(fixed::isqrtRound(15) == 4);
  CHECK(fixed::isqrtRound(12) == 3);
  CHECK(fixed::isqrtFloor(std::uint64_t{1} << 62) == std::uint64_t{1} << 31);
  Random r(5);
  for (int i = 0; i < 10000; ++i) {
    const double x = r.uniform(-1e6, 1e6), y = r.uniform(-1e6, 1e6);
    const double a = fixed::atan2Q30(std::llround(y), std::llround(x)) / 1073741824.0;
    REQUIRE(a == Approx(std::atan2(std::llround(y), std::llround(x))).margin(2e-7));
    const double ang = r.uniform(-std::numbers::pi, std::numbers::pi);
    std::int64_t s, c;
    fixed::sinCosQ30(std::llround(ang * 1073741824.0), s, c);
    REQUIRE(s / 1073741824.0 == Approx(std::sin(ang)).margin(2e-7));
    REQUIRE(c / 1073741824.0 == Approx(std::cos(ang)).margin(2e-7));
  }
}

namespace {

InnerLoopParams mkInnerParams(double kp, double kd, double kyaw) {
  const RotorParams rp = *preset("mk_quad");
  const Allocation al(plusRotors(0.225), rp);
  InnerLoopParams p;
  p.attitude_kp = kp;
  p.attitude_kd = kd;
  p.yaw_rate_kp = kyaw;
  Eigen::Matrix4d scale = Eigen::Matrix4d::Identity();
  scale.topLeftCorner<3, 3>() = p.inertia;
  p.mixer = al.inverse() * scale;
  p.max_rotor_speed = rp.max_rotor_speed;
  p.max_thrust = al.matrix().row(3).sum() * rp.max_rotor_speed * rp.max_rotor_speed;
  return p;
}

// compares the integer loop with its float reference on random inputs; returns the worst gaps
struct Gaps {
  std::int64_t estimate = 0, command = 0;
};

Gaps compare(const InnerLoopParams& p, int cases, std::uint64_t seed) {
  const InnerLoopFixed fixedLoop(p);
  Random r(seed);
  Gaps worst;
  const double gyro_max = 17.45 / p.gyro_lsb, accel_max = 176.5 / p.accel_lsb, g_counts = 9.81 / p.accel_lsb;
  for (int i = 0; i < cases; ++i) {
    AttitudeEstimate prior{static_cast<std::int32_t>(std::llround(r.uniform(-1.2, 1.2) * 1048576.0)),
                           static_cast<std::int32_t>(std::llround(r.uniform(-1.2, 1.2) * 1048576.0))};
    std::array<std::int32_t, 3> gyro{}, accel{};
    for (auto& v : gyro) v = static_cast<std::int32_t>(std::llround(r.uniform(-gyro_max, gyro_max)));
    // half the cases near 1 g (the filter corrects), half anywhere in range
    const bool near_g = r.uniform() < 0.5;
    for (auto& v : accel)
      v = static_cast<std::int32_t>(
          std::llround(near_g ? r.uniform(-0.7, 0.7) * g_counts : r.uniform(-accel_max, accel_max)));
    InnerCommand c;
    c.roll_q12 = static_cast<std::int32_t>(std::llround(r.uniform(-0.6, 0.6) * 4096));
    c.pitch_q12 = static_cast<std::int32_t>(std::llround(r.uniform(-0.6, 0.6) * 4096));
    c.yaw_rate_q12 = static_cast<std::int32_t>(std::llround(r.uniform(-10, 10) * 4096));
    c.thrust_q16 = static_cast<std::int32_t>(std::llround(r.uniform(-5, 45) * 65536));  // beyond both limits too
    const InnerOutput f = fixedLoop.evaluate(prior, gyro, accel, c);
    const InnerOutput d = innerLoopFloat(p, prior, gyro, accel, c);
    worst.estimate =
        std::max({worst.estimate,
                  std::abs(fixed::roundShift(f.estimate.roll_q20, 8) - fixed::roundShift(d.estimate.roll_q20, 8)),
                  std::abs(fixed::roundShift(f.estimate.pitch_q20, 8) - fixed::roundShift(d.estimate.pitch_q20, 8))});
    REQUIRE(f.motors == 4);
    REQUIRE(d.motors == 4);
    for (std::size_t k = 0; k < f.motors; ++k)
      worst.command =
          std::max<std::int64_t>(worst.command, std::abs(int(f.motor_commands[k]) - int(d.motor_commands[k])));
  }
  return worst;
}

}  // namespace

TEST_CASE("the integer inner loop agrees with its float reference within 1 LSB", "[quadrotor][fixed]") {
  // gains on the Q8 grid, as the integer code holds them
  const Gaps g = compare(mkInnerParams(200.0, 25.0, 8.0), 200000, 1);
  INFO("worst estimate gap " << g.estimate << " LSB (Q12 rad), worst motor command gap " << g.command);
  CHECK(g.estimate <= 1);
  CHECK(g.command <= 1);
}

TEST_CASE("the attitude filter blends across +-pi the shorter way, in both implementations", "[quadrotor][fixed]") {
  // upside down: the estimate at +179 deg, the accelerometer's gravity direction at -179 deg;
  // they are 2 deg apart, and the blend moves the estimate 2 (1 - w) deg further round
  const InnerLoopParams p = mkInnerParams(200.0, 25.0, 8.0);
  const InnerLoopFixed fixedLoop(p);
  const double w = p.filter_gyro_weight, g_counts = p.gravity / p.accel_lsb, deg = std::numbers::pi / 180;
  for (const double sign : {1.0, -1.0}) {
    const AttitudeEstimate prior{static_cast<std::int32_t>(std::llround(sign * 179 * deg * 1048576.0)), 0};
    const std::array<std::int32_t, 3> gyro{}, accel{
        0, static_cast<std::int32_t>(std::llround(std::sin(-sign * 179 * deg) * g_counts)),
        static_cast<std::int32_t>(std::llround(std::cos(-sign * 179 * deg) * g_counts))};
    double expected = sign * (179 + 2 * (1 - w)) * deg;
    if (expected > std::numbers::pi) expected -= 2 * std::numbers::pi;
    if (expected < -std::numbers::pi) expected += 2 * std::numbers::pi;
    const InnerOutput f = fixedLoop.evaluate(prior, gyro, accel, InnerCommand{});
    const InnerOutput d = innerLoopFloat(p, prior, gyro, accel, InnerCommand{});
    CHECK(f.estimate.roll_q20 / 1048576.0 == Approx(expected).margin(1e-3 * deg));
    CHECK(d.estimate.roll_q20 / 1048576.0 == Approx(expected).margin(1e-3 * deg));
  }
}

TEST_CASE("the integer inner loop does not overflow at the largest gains", "[quadrotor][fixed]") {
  // the largest gains the driver accepts, far beyond useful tuning, and inputs at full scale
  InnerLoopParams p =
      mkInnerParams(InnerLoopLimits::attitude_kp, InnerLoopLimits::attitude_kd, InnerLoopLimits::yaw_rate_kp);
  p.max_angular_acceleration = InnerLoopLimits::max_angular_acceleration;
  const Gaps g = compare(p, 50000, 2);
  CHECK(g.estimate <= 1);
  CHECK(g.command <= 1);
}

TEST_CASE("ground effect: the thrust gain at three heights is Cheeseman-Bennett's", "[quadrotor][fidelity]") {
  const RotorParams p = *preset("mk_quad");
  const double R = p.rotor_radius;
  RotorModel model(plusRotors(0.225), p);
  model.setSpeeds({400, 410, 420, 430});
  Vec3 f0, t0;
  model.wrench(Vec3::Zero(), Vec3::Zero(), f0, t0);
  for (double h : {0.1, 0.2, 0.5}) {
    const double expected = 1.0 / (1.0 - std::pow(R / (4 * h), 2));
    CHECK(groundEffectGain(h, R) == Approx(expected).epsilon(1e-12));
    model.setThrustGains(std::vector<double>(4, groundEffectGain(h, R)));
    Vec3 f, t;
    model.wrench(Vec3::Zero(), Vec3::Zero(), f, t);
    CHECK(f.z() / f0.z() == Approx(expected).epsilon(1e-12));
    CHECK(t.z() / t0.z() == Approx(expected).epsilon(1e-12));  // reaction torque scales with thrust
  }
  // far up it fades (2 m: 0.025 %), and below R/2 the gain holds at 4/3
  CHECK(groundEffectGain(2.0, R) == Approx(1.0).margin(3e-4));
  CHECK(groundEffectGain(0.01, R) == Approx(4.0 / 3.0).epsilon(1e-12));
}

TEST_CASE("ground effect in flight: a quadrotor low over the ground gets the gain of its rotors' height",
          "[quadrotor][fidelity]") {
  // from hover speed; the difference in vertical acceleration with and without the effect
  // is (gain - 1) times the thrust, about m g
  const double R = preset("mk_quad")->rotor_radius;
  for (double h : {0.15, 0.25, 0.5}) {  // rotor height; the rotors sit 2 cm above the body's origin
    double accel[2];
    for (int on = 0; on < 2; ++on) {
      const std::string xml = "<scene><environment timestep=\"0.002\" seed=\"1\"/><type name=\"q\" file=\"mk_quad.xml\"/>"
                              "<ground/><artifact name=\"q\" type=\"q\" xyz=\"0 0 " + std::to_string(h - 0.02) +
                              "\"><driver ground_effect=\"" + (on ? "true" : "false") + "\"/></artifact></scene>";
      Scene scene = loadSceneFromString(xml, "ground_effect.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
      scene.environment->step(2);  // the driver's first forces act in the second step's physics
      accel[on] = scene.environment->findArtifact("q")->state().linear_acceleration.z();
    }
    const double gain = 1.0 / (1.0 - std::pow(R / (4 * h), 2));
    INFO("h = " << h << " m: gain " << gain);
    CHECK(accel[1] - accel[0] == Approx((gain - 1) * 9.81).epsilon(0.02));
  }
}
