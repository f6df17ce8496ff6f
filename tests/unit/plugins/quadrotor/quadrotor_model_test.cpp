// The quadrotor model and controller: spec section 7 checks, fixed point against its float
// reference, IMU statistics, and closed-loop flight.
#include "fixed_point.hpp"
#include "quadrotor_model.hpp"
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
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
  const RotorParams p = RotorParams{};
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
  const RotorParams p = RotorParams{};
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
  auto model = std::make_shared<RotorModel>(std::vector<Rotor>{{Vec3::Zero(), 1}}, RotorParams{});
  a.setDriver(std::make_unique<test::LambdaDriver>([model](Driver& d, const StepInfo&) {
    model->step(0.001, std::vector<double>{500.0});
    Vec3 f, t;
    model->wrench(Vec3::Zero(), Vec3::Zero(), f, t);
    d.artifact().root().addTorque(t, Frame::Local);
  }));
  env.step(200);
  CHECK(a.state().angular_velocity.z() < -0.1);  // clockwise seen from above
  CHECK(std::abs(a.state().angular_velocity.x()) < 1e-9);
}

TEST_CASE("the allocation times its inverse is the identity", "[quadrotor]") {
  // the mk_quad's constants, and a crazyflie's (kF three orders of magnitude smaller)
  RotorParams small;
  small.thrust_coefficient = 2.27e-8;
  small.moment_constant = 6.9929e-3;
  for (const RotorParams& p : {RotorParams{}, small}) {
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
  const Allocation al(hexa, RotorParams{});
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

TEST_CASE("fixed-point helpers: the fast square root is the bitwise one's integer, lanes are independent",
          "[quadrotor][fixed]") {
  // every n below 2^20, squares and their neighbours up to 2^64, random n of every magnitude
  for (std::uint64_t n = 0; n < (1u << 20); ++n) REQUIRE(fixed::isqrtFloor(n) == fixed::isqrtFloorBitwise(n));
  Random r(11);
  auto check = [](std::uint64_t n) {
    INFO("n = " << n);
    REQUIRE(fixed::isqrtFloor(n) == fixed::isqrtFloorBitwise(n));
  };
  for (std::uint64_t k : {std::uint64_t{1} << 26, (std::uint64_t{1} << 26) - 1, (std::uint64_t{1} << 26) + 1,
                          std::uint64_t{94906265}, (std::uint64_t{1} << 32) - 1})
    for (std::uint64_t n : {k * k - 1, k * k, k * k + 1}) check(n);
  for (int i = 0; i < 200000; ++i) {
    const int bits = 1 + static_cast<int>(r() % 63);
    const std::uint64_t n = r() >> (64 - bits);
    check(n);
    const std::uint64_t k = n >> (bits / 2 + 1);  // a root of about half the bits
    for (std::uint64_t m : {k * k - 1, k * k, k * k + 1}) check(m);
  }
  check(~std::uint64_t{0});
  // two lanes give what each gives alone
  for (int i = 0; i < 10000; ++i) {
    const std::int64_t y0 = static_cast<std::int64_t>(r() % 2000001) - 1000000, x0 = static_cast<std::int64_t>(r() % 2000001) - 1000000;
    const std::int64_t y1 = i % 7 == 0 ? 0 : static_cast<std::int64_t>(r() % 2000001) - 1000000;
    const std::int64_t x1 = i % 7 == 0 ? 0 : static_cast<std::int64_t>(r() % 2000001) - 1000000;
    const auto both = fixed::atan2Q30<2>({y0, y1}, {x0, x1});
    REQUIRE(both[0] == fixed::atan2Q30(y0, x0));
    REQUIRE(both[1] == fixed::atan2Q30(y1, x1));
    const std::int64_t a0 = std::llround(r.uniform(-std::numbers::pi, std::numbers::pi) * 1073741824.0);
    const std::int64_t a1 = std::llround(r.uniform(-std::numbers::pi, std::numbers::pi) * 1073741824.0);
    std::array<std::int64_t, 2> s{}, c{};
    fixed::sinCosQ30<2>({a0, a1}, s, c);
    std::int64_t s0, c0, s1, c1;
    fixed::sinCosQ30(a0, s0, c0);
    fixed::sinCosQ30(a1, s1, c1);
    REQUIRE((s[0] == s0 && c[0] == c0 && s[1] == s1 && c[1] == c1));
  }
}

namespace {

InnerLoopParams mkInnerParams(double kp, double kd, double kyaw) {
  const RotorParams rp = RotorParams{};
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

Gaps compare(const InnerLoopParams& p, int cases, std::uint64_t seed, InnerMode mode = InnerMode::Attitude) {
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
    const InnerOutput f = fixedLoop.evaluate(prior, gyro, accel, c, mode);
    const InnerOutput d = innerLoopFloat(p, prior, gyro, accel, c, mode);
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

TEST_CASE("in rates mode the integer inner loop agrees with its float reference within 1 LSB", "[quadrotor][fixed]") {
  // (roll and pitch carry body rates of up to +-0.6 rad/s there)
  for (const InnerLoopParams& p : {mkInnerParams(200.0, 25.0, 8.0),
                                   mkInnerParams(InnerLoopLimits::attitude_kp, InnerLoopLimits::attitude_kd,
                                                 InnerLoopLimits::yaw_rate_kp)}) {
    const Gaps g = compare(p, 50000, 3, InnerMode::Rates);
    INFO("kd " << p.attitude_kd << ": worst motor command gap " << g.command);
    CHECK(g.estimate <= 1);
    CHECK(g.command <= 1);
  }
}

TEST_CASE("in rates mode the inner loop holds body rates, not angles", "[quadrotor][fixed]") {
  const InnerLoopParams p = mkInnerParams(200.0, 25.0, 8.0);
  const InnerLoopFixed loop(p);
  // tilted 0.3 rad in roll, not turning, level command: attitude mode turns it back, rates mode
  // (a zero rate) leaves it; a rate command turns it whatever its angle
  const AttitudeEstimate tilted{static_cast<std::int32_t>(0.3 * 1048576), 0};
  const std::array<std::int32_t, 3> still{}, gravity{0, 0, static_cast<std::int32_t>(9.81 / p.accel_lsb)};
  InnerCommand level;
  level.thrust_q16 = 8 << 16;
  CHECK(loop.evaluate(tilted, still, gravity, level, InnerMode::Attitude).angular_acceleration_q12[0] < 0);
  CHECK(loop.evaluate(tilted, still, gravity, level, InnerMode::Rates).angular_acceleration_q12[0] == 0);
  InnerCommand roll_rate = level;
  roll_rate.roll_q12 = 4096;  // 1 rad/s
  const auto alpha = loop.evaluate(tilted, still, gravity, roll_rate, InnerMode::Rates).angular_acceleration_q12;
  CHECK(alpha[0] / 4096.0 == Approx(p.attitude_kd * 1.0).margin(0.01));
  CHECK(alpha[1] == 0);
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
  const RotorParams p = RotorParams{};
  const double R = p.rotor_radius;
  RotorModel model(plusRotors(0.225), p);
  model.setSpeeds(std::vector<double>{400, 410, 420, 430});
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
  const double R = RotorParams{}.rotor_radius;
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

TEST_CASE("battery: thrust at a fixed command follows (U - 7.575 V), the voltage sags with current", "[quadrotor][fidelity]") {
  BatteryParams bp;
  Battery battery(bp);
  RotorModel model(plusRotors(0.225), RotorParams{});
  model.setSpeeds(std::vector<double>{500, 500, 500, 500});
  auto thrustAt = [&](double volts) {
    model.setThrustGains(std::vector<double>(4, battery.thrustGain(volts)));
    Vec3 f, t;
    model.wrench(Vec3::Zero(), Vec3::Zero(), f, t);
    return f.z();
  };
  CHECK(thrustAt(16.0) / thrustAt(14.5) == Approx((16.0 - 7.575) / (14.5 - 7.575)).epsilon(1e-9));
  CHECK(battery.thrustGain(15.5) == 1.0);
  // under load: U = U_oc - R P / (eta U), and the charge drops by I dt / C
  CHECK(battery.voltage() == 16.8);
  const double power = 120.0;  // W of mechanical power, about what an mk_quad takes to hover (EST)
  battery.step(10.0, power);
  const double u = battery.voltage();
  CHECK(u == Approx(16.8 - bp.resistance * power / (bp.efficiency * u)).epsilon(1e-12));
  CHECK(battery.charge() == Approx(1.0 - power / bp.efficiency / u * 10.0 / (3600.0 * bp.capacity)).epsilon(1e-12));
  CHECK(battery.openCircuit() < 16.8);
}

TEST_CASE("the MK serial link: thrust in steps of m g / 128 up to 255, angles in whole steps", "[quadrotor][fidelity]") {
  const double m = 0.82, g = 9.81, unit = m * g / 128, step = 0.5 * std::numbers::pi / 180;
  const AttitudeCommand c = linkCommand({0.0123, -0.0311, 0.7, 8.1234}, m, g, step);
  CHECK(c.thrust == Approx(std::round(8.1234 / unit) * unit).epsilon(1e-15));
  CHECK(c.roll == Approx(std::round(0.0123 / step) * step).epsilon(1e-15));
  CHECK(c.pitch == Approx(std::round(-0.0311 / step) * step).epsilon(1e-15));
  CHECK(c.yaw_rate == 0.7);
  CHECK(linkCommand({0, 0, 0, 100.0}, m, g, step).thrust == Approx(255 * unit));
  CHECK(linkCommand({0, 0, 0, -1.0}, m, g, step).thrust == 0.0);
}

namespace {

// hovers one mk_quad 1 m up for `seconds` with the driver attributes given; returns the mean
// height error (set-point minus position) over the last 2 s
double hoverError(const std::string& driver_attributes, double seconds) {
  const std::string xml = "<scene><environment timestep=\"0.002\" seed=\"3\"/><type name=\"q\" file=\"mk_quad.xml\"/>"
                          "<ground/><artifact name=\"q\" type=\"q\" xyz=\"0 0 1\"><driver " + driver_attributes +
                          "/></artifact></scene>";
  Scene scene = loadSceneFromString(xml, "hover.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
  Environment& env = *scene.environment;
  const Artifact& q = *env.findArtifact("q");
  const auto steps = static_cast<int>(seconds / 0.002);
  double sum = 0;
  int n = 0;
  for (int k = 0; k < steps; ++k) {
    env.step();
    if (k >= steps - 1000) sum += 1.0 - q.pose().position.z(), ++n;
  }
  return sum / n;
}

}  // namespace

TEST_CASE("mass mismatch: hover offset eps g / Kp with the thrust estimator off, back under 5 mm with it on",
          "[quadrotor][fidelity]") {
  // the vehicle is 5 % heavier than the controller believes: eps = m / m_c - 1 = 0.05; no integral
  // on z (position_ki "4.5 4.5 0"), position_kp 9
  const std::string mismatch = "controller_mass=\"" + std::to_string(0.82 / 1.05) + "\"";
  const double expected = 0.05 * 9.81 / 9.0;
  // measured from the matched vehicle's own offset (its 8-bit motor commands leave one of a few mm)
  const double matched = hoverError("", 12.0);
  const double off = hoverError(mismatch, 12.0) - matched;
  INFO("offset " << off << " m beyond the matched vehicle's " << matched << " m, expected " << expected << " m");
  CHECK(off == Approx(expected).epsilon(0.05));
  const double on = hoverError(mismatch + " thrust_estimator=\"true\"", 20.0);
  INFO("with the estimator: " << on << " m");
  CHECK(std::abs(on) < 0.005);
  // a battery that sags is what the estimator is also for
  CHECK(std::abs(hoverError("battery=\"true\" thrust_estimator=\"true\"", 20.0)) < 0.005);
}

TEST_CASE("command delay: the vehicle answers a set-point step `command_delay` later, within one inner-loop period",
          "[quadrotor][fidelity]") {
  // when does the attitude of a run whose set-point steps at 1 s first differ from one whose does not?
  auto divergence = [](const std::string& delay) {
    std::vector<std::vector<Quat>> attitude(2);
    for (int stepped = 0; stepped < 2; ++stepped) {
      const std::string xml = "<scene><environment timestep=\"0.002\" seed=\"3\"/><type name=\"q\" file=\"mk_quad.xml\"/>"
                              "<artifact name=\"q\" type=\"q\" xyz=\"0 0 1\"><driver reference=\"external\" "
                              "command_delay=\"" + delay + "\"/></artifact></scene>";
      Scene scene = loadSceneFromString(xml, "delay.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
      Environment& env = *scene.environment;
      Artifact& q = *env.findArtifact("q");
      env.start();
      for (int k = 0; k < 1000; ++k) {
        if (k == 500 && stepped == 1) {
          Setpoint sp;
          sp.position = Vec3(0.5, 0, 1);
          dynamic_cast<SetpointInterface*>(q.driver())->setSetpoint(sp);
        }
        env.step();
        attitude[static_cast<std::size_t>(stepped)].push_back(q.pose().orientation);
      }
    }
    for (std::size_t k = 0; k < attitude[0].size(); ++k)
      if (!attitude[0][k].isApprox(attitude[1][k], 1e-12)) return static_cast<double>(k) * 0.002;
    return -1.0;
  };
  const double now = divergence("0"), late = divergence("0.012");
  INFO("the attitude answers at " << now << " s without delay, " << late << " s with 12 ms");
  REQUIRE(now > 0);
  CHECK(std::abs((late - now) - 0.012) <= 0.002 + 1e-9);
}

TEST_CASE("Dryden turbulence: the spectrum of each component within 10 % at three frequencies", "[quadrotor][fidelity]") {
  // 10 m up, W20 = 7.7 m/s (15 knots, light turbulence), flying through it at 5 m/s, sampled at 500 Hz
  const auto scales = DrydenTurbulence::scales(10.0, 7.7);
  const double V = 5.0, dt = 0.002;
  // Welch: Hann-windowed segments of 16 s (0.06 Hz apart: little leakage from the steep low end), averaged
  const std::size_t segment = 8192, segments = 1200;  // the estimate scatters about 3 % (1 / sqrt(1200))
  DrydenTurbulence turbulence;
  Random random(42);
  for (int k = 0; k < 20000; ++k) (void)turbulence.step(dt, scales, V, random);  // settle
  const std::array<double, 3> hz{1.0, 2.0, 5.0};
  std::array<std::array<double, 3>, 3> power{};  // [axis][frequency]
  std::array<double, 3> variance{};
  std::vector<Vec3> x(segment);
  double window_power = 0;
  for (std::size_t n = 0; n < segment; ++n) {
    const double w = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * static_cast<double>(n) / static_cast<double>(segment));
    window_power += w * w;
  }
  for (std::size_t s = 0; s < segments; ++s) {
    for (auto& v : x) v = turbulence.step(dt, scales, V, random);
    for (int axis = 0; axis < 3; ++axis) {
      for (const auto& v : x) variance[axis] += v[axis] * v[axis] / static_cast<double>(segment * segments);
      for (std::size_t f = 0; f < hz.size(); ++f) {
        double re = 0, im = 0;
        for (std::size_t n = 0; n < segment; ++n) {
          const double w = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * static_cast<double>(n) / static_cast<double>(segment));
          const double phase = 2 * std::numbers::pi * hz[f] * static_cast<double>(n) * dt;
          re += w * x[n][axis] * std::cos(phase);
          im -= w * x[n][axis] * std::sin(phase);
        }
        // one-sided density per Hz: 2 |X|^2 dt / sum(w^2)
        power[axis][f] += 2 * (re * re + im * im) * dt / window_power / static_cast<double>(segments);
      }
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (std::size_t f = 0; f < hz.size(); ++f) {
      // per Hz = per rad/s times 2 pi
      const double expected = 2 * std::numbers::pi * DrydenTurbulence::spectrum(axis, 2 * std::numbers::pi * hz[f], scales, V);
      INFO("axis " << axis << " at " << hz[f] << " Hz: " << power[axis][f] << " vs " << expected);
      CHECK(power[axis][f] == Approx(expected).epsilon(0.10));
    }
  }
  // and the variances are the scales' (the long correlation of u makes its estimate the loosest)
  CHECK(std::sqrt(variance[0]) == Approx(scales.sigma_u).epsilon(0.15));
  CHECK(std::sqrt(variance[1]) == Approx(scales.sigma_v).epsilon(0.10));
  CHECK(std::sqrt(variance[2]) == Approx(scales.sigma_w).epsilon(0.10));
}

TEST_CASE("downwash: the drop below another robot at known offsets is the fitted model's", "[quadrotor][fidelity]") {
  // gym-pybullet-drones' Crazyflie coefficients
  const double R = 0.0231, c1 = 2267.18, c2 = 0.16, c3 = -0.11;
  for (const auto& [dz, dxy] : {std::pair{0.3, 0.0}, std::pair{0.5, 0.02}, std::pair{1.0, 0.05}}) {
    const double beta = c2 * dz + c3;
    CHECK(downwashForce(dz, dxy, R, c1, c2, c3, 0.1) ==
          Approx(-c1 * std::pow(R / (4 * dz), 2) * std::exp(-0.5 * std::pow(dxy / beta, 2))).epsilon(1e-12));
  }
  CHECK(downwashForce(-0.5, 0.0, R, c1, c2, c3, 0.1) == 0.0);  // nobody above
  CHECK(downwashForce(0.05, 0.0, R, c1, c2, c3, 0.1) == 0.0);  // beside, not above
}

namespace {

// the vertical and x accelerations of artifact `name` after two steps (the first forces act in the
// second step's physics), in a scene of `artifacts` over the examples' artifact types
Vec3 accelerationAfterTwoSteps(const std::string& artifacts, const std::string& name) {
  const std::string xml = "<scene><environment timestep=\"0.002\" seed=\"1\"/><type name=\"cf\" file=\"crazyflie.xml\"/>"
                          "<type name=\"q\" file=\"mk_quad.xml\"/>" + artifacts + "</scene>";
  Scene scene = loadSceneFromString(xml, "air.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
  scene.environment->step(2);
  return scene.environment->findArtifact(name)->state().linear_acceleration;
}

}  // namespace

TEST_CASE("downwash in flight: a Crazyflie 0.5 m below another drops by the model's force", "[quadrotor][fidelity]") {
  auto pair = [](const char* on) {
    std::string scene = "<artifact name=\"up\" type=\"cf\" xyz=\"0 0 1.5\"/>";
    scene += "<artifact name=\"low\" type=\"cf\" xyz=\"0.02 0 1.0\"><driver downwash=\"";
    scene += on;
    scene += "\"/></artifact>";
    return scene;
  };
  const double off = accelerationAfterTwoSteps(pair("false"), "low").z();
  const double on = accelerationAfterTwoSteps(pair("true"), "low").z();
  const double force = downwashForce(0.5, 0.02, 0.0231, 2267.18, 0.16, -0.11, 0.1);
  CHECK((on - off) * 0.029 == Approx(force).epsilon(0.02));  // crazyflie.xml: 29 g
  // the upper one feels nothing from the one below
  CHECK(accelerationAfterTwoSteps(pair("true"), "up").z() == accelerationAfterTwoSteps(pair("false"), "up").z());
}

TEST_CASE("wind: a hovering quadrotor in a 3 m/s wind is pushed by its rotors' drag", "[quadrotor][fidelity]") {
  const double still = accelerationAfterTwoSteps("<artifact name=\"q\" type=\"q\" xyz=\"0 0 1\"/>", "q").x();
  const double windy =
      accelerationAfterTwoSteps("<artifact name=\"q\" type=\"q\" xyz=\"0 0 1\"><driver wind=\"3 0 0\"/></artifact>", "q").x();
  // four rotors near hover speed: F = 4 w_h lambda1 V
  const RotorParams p = RotorParams{};
  const double w_h = std::sqrt(0.82 * 9.81 / (4 * p.thrust_coefficient));
  CHECK((windy - still) * 0.82 == Approx(4 * w_h * p.rotor_drag_coefficient * 3.0).epsilon(0.02));
}

TEST_CASE("a 1-cosine gust begins to act at gust_start", "[quadrotor][fidelity]") {
  // the first step whose state differs from a run without the gust, and the last whose force does
  auto trace = [](const std::string& gust) {
    const std::string xml = "<scene><environment timestep=\"0.002\" seed=\"1\"/><type name=\"q\" file=\"mk_quad.xml\"/>"
                            "<artifact name=\"q\" type=\"q\" xyz=\"0 0 1\"><driver " + gust + "/></artifact></scene>";
    Scene scene = loadSceneFromString(xml, "gust.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
    std::vector<Vec3> a;
    for (int k = 0; k < 600; ++k) {
      scene.environment->step();
      a.push_back(scene.environment->findArtifact("q")->state().linear_acceleration);
    }
    return a;
  };
  const auto calm = trace("");
  const auto gusty = trace("gust=\"2 0 0\" gust_start=\"0.4\" gust_duration=\"0.3\"");
  std::size_t first = 0;
  while (first < calm.size() && calm[first] == gusty[first]) ++first;
  // the driver of step k writes forces for step k + 1's physics; the gust is 0 at gust_start itself
  CHECK(static_cast<double>(first + 1) * 0.002 == Approx(0.4 + 2 * 0.002).margin(1e-9));  // state k: time (k + 1) dt
}

TEST_CASE("a command delay off the inner loop's period and inconsistent battery voltages are refused while loading",
          "[quadrotor][fidelity]") {
  auto load = [](const std::string& driver) {
    const std::string xml = "<scene><environment timestep=\"0.002\"/><type name=\"q\" file=\"mk_quad.xml\"/>"
                            "<artifact name=\"q\" type=\"q\" xyz=\"0 0 1\"><driver " + driver + "/></artifact></scene>";
    try {
      (void)loadSceneFromString(xml, "refused.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("loaded");  // the scene is not started: a refusal at start would not show here
  };
  CHECK_THAT(load("command_delay=\"0.003\""),
             Catch::Contains("command_delay must be a whole number of inner-loop periods (2.000000 ms)"));
  CHECK_THAT(load("battery=\"true\" battery_empty_voltage=\"17\""),
             Catch::Contains("battery: needs battery_zero_thrust_voltage < battery_empty_voltage < battery_full_voltage"));
  CHECK(load("command_delay=\"0.004\" battery=\"true\"") == "loaded");
}

TEST_CASE("a swarm's drivers share their parsed parameters, yet every type flies with its own mass and every member "
          "with its own values",
          "[quadrotor]") {
  // two types alike but for the body's mass, with the same driver parameters: the drivers parse
  // those once and work out an airframe per type (PluginSetup::shared)
  const fs::path dir = "quadrotor_shared_test";
  fs::create_directories(dir);
  std::ifstream in(fs::path(SSX_EXAMPLES_DIR) / "artifacts" / "mk_quad.xml");
  std::string light((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string heavy = light;
  const auto at = heavy.find("mass=\"0.82\"");
  REQUIRE(at != std::string::npos);
  heavy.replace(at, 11, "mass=\"1.20\"");
  std::ofstream(dir / "light.xml") << light;
  std::ofstream(dir / "heavy.xml") << heavy;
  const std::string xml =
      "<scene><environment timestep=\"0.002\" seed=\"1\"/><type name=\"light\" file=\"light.xml\"/>"
      "<type name=\"heavy\" file=\"heavy.xml\"/><ground/>"
      "<artifact name=\"l\" type=\"light\" xyz=\"0 -5 1\"/><artifact name=\"h\" type=\"heavy\" xyz=\"0 5 1\"/>"
      "<swarm type=\"light\" count=\"3\" name=\"m{i}\" xyz=\"0 0 1\" spacing=\"1\" columns=\"3\"><driver target=\"{i}.5 0 1.5\"/>"
      "</swarm></scene>";
  Scene scene = loadSceneFromString(xml, "shared.xml", dir);
  Environment& env = *scene.environment;
  env.step(2);  // the driver's first forces act in the second step's physics
  // each starts with its rotors at its own hover speed: with the light one's airframe the heavy
  // one would fall at (0.82 - 1.2) / 1.2 g = -3.1 m/s^2
  CHECK(std::abs(env.findArtifact("l")->state().linear_acceleration.z()) < 0.3);
  CHECK(std::abs(env.findArtifact("h")->state().linear_acceleration.z()) < 0.3);
  env.step(2500);  // 5 s
  for (int i = 0; i < 3; ++i) {
    const Vec3 p = env.findArtifact("m" + std::to_string(i))->pose().position;
    INFO("member " << i << " at " << p.transpose());
    CHECK((p - Vec3(i + 0.5, 0, 1.5)).norm() < 0.05);
  }
}
