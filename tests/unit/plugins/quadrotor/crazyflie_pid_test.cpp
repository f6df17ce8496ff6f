// The Crazyflie firmware's controller, loop by loop: pid.c's element (D on the measurement, the
// integral's and the output's clamps, wrapped yaw errors); the position loop asks for no more than
// 1.1 m/s and the velocity loop tilts no more than 20 degrees, in the frame turned by the vehicle's
// yaw; hover takes the thrust base (36000) and no tilt compensation; the mixer gives up collective
// thrust first; a command is newtons per motor; a saved state continues identically.
#include "crazyflie_pid.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <numbers>

using namespace ssx;
using namespace ssx::quadrotor;

namespace {

// a vehicle that stands where the test puts it
struct Standing : FlightInputs {
  Pose pose;
  Vec3 velocity = Vec3::Zero(), rates = Vec3::Zero();
  Setpoint setpoint;
  bool heading = true;
  Setpoint reference(double, double) override { return setpoint; }
  bool holdsHeading() const override { return heading; }
  void position(Pose& p, Vec3& v) const override { p = pose, v = velocity; }
  Vec3 bodyRates() const override { return rates; }
};

// the Crazyflie's X: front-right, rear-right, rear-left, front-left (M1..M4), M1 and M3 spinning alike
std::vector<Rotor> xFrame() {
  const double a = 0.046 * std::sqrt(0.5);
  return {{Vec3(a, -a, 0), 1}, {Vec3(-a, -a, 0), -1}, {Vec3(-a, a, 0), 1}, {Vec3(a, a, 0), -1}};
}

RotorParams crazyflieRotors() {
  RotorParams r;
  r.thrust_coefficient = 2.27e-8;
  return r;
}

}  // namespace

TEST_CASE("crazyflie_pid: the PID element", "[quadrotor][crazyflie]") {
  Pid p({2, 1, 0.5, 0.3, 4});
  CHECK(p.update(1, 0, 0.1) == Approx(2 * 1 + 1 * 0.1));  // no derivative kick from the set-point
  CHECK(p.update(1, 0.2, 0.1) == Approx(2 * 0.8 + 1 * 0.18 + 0.5 * (-0.2 / 0.1)));
  for (int i = 0; i < 100; ++i) p.update(1, 0.2, 0.1);
  CHECK(p.integral() == Approx(0.3));                     // clamped
  CHECK(p.update(100, 0.2, 0.1) == 4);                    // output clamped
  Pid yaw({1, 0, 0});
  CHECK(yaw.update(170, -170, 0.002, true) == Approx(-20));  // the short way round
}

TEST_CASE("crazyflie_pid: the gyro's two-pole low-pass passes DC, halves the power at its cut-off", "[quadrotor][crazyflie]") {
  // the firmware's: 80 Hz at 1 kHz; the amplitude of a sine after the transient
  auto gain = [](double hz) {
    LowPass2 f(1000, 80);
    double highest = 0;
    for (int i = 0; i < 4000; ++i) {
      const double out = f.apply(std::sin(2 * std::numbers::pi * hz * i / 1000.0));
      if (i >= 2000) highest = std::max(highest, std::abs(out));
    }
    return highest;
  };
  LowPass2 dc(1000, 80);
  double out = 0;
  for (int i = 0; i < 200; ++i) out = dc.apply(3.0);
  CHECK(out == Approx(3.0).epsilon(1e-9));
  CHECK(gain(5) == Approx(1).margin(0.01));
  CHECK(gain(80) == Approx(std::sqrt(0.5)).margin(0.02));
  CHECK(gain(300) < 0.1);
}

TEST_CASE("crazyflie_pid: hover, limits, the yaw frame, no tilt compensation", "[quadrotor][crazyflie]") {
  const CrazyfliePidGains gains;
  Standing in;
  in.pose.position = Vec3(0, 0, 1);
  in.setpoint.position = Vec3(0, 0, 1);
  CrazyfliePidController c(gains, xFrame(), crazyflieRotors());
  std::array<double, 4> speeds{};
  c.step(0, 0, in, speeds);
  // on the set-point, at rest: the thrust base, every motor alike, each 36000/65535 of 0.12 N
  CHECK(c.desiredAttitude()[2] == 36000);
  for (const double m : c.motorCommands()) CHECK(m == 36000);
  for (const double t : c.motorThrusts()) CHECK(t == Approx(36000.0 / 65535 * 0.12).epsilon(1e-9));
  CHECK(speeds[0] == Approx(std::sqrt(36000.0 / 65535 * 0.12 / 2.27e-8)).epsilon(1e-9));
  // 1 m behind in x: 2 m/s asked, 1.1 m/s allowed; 25 degrees per m/s, 20 allowed, nose down towards +x
  in.setpoint.position = Vec3(1, 0, 1);
  c.step(5, 0.01, in, speeds);
  CHECK(c.desiredVelocity().x() == Approx(1.1));
  CHECK(c.desiredAttitude()[1] == Approx(20));
  CHECK(c.desiredAttitude()[0] == Approx(0).margin(1e-12));
  // turned 90 degrees left, the same error is along the body's -y: the vehicle rolls, positive (right side down)
  Standing turned = in;
  turned.pose.orientation = Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ()));
  CrazyfliePidController d(gains, xFrame(), crazyflieRotors());
  d.step(0, 0, turned, speeds);
  CHECK(d.desiredVelocity().x() == Approx(1.1));
  CHECK(d.desiredAttitude()[0] == Approx(20));
  CHECK(d.desiredAttitude()[1] == Approx(0).margin(1e-9));
  // tilted by 15 degrees, on the set-point: the same thrust (no compensation for the tilt)
  Standing tilted;
  tilted.pose.position = tilted.setpoint.position = Vec3(0, 0, 1);
  tilted.pose.orientation = Quat(Eigen::AngleAxisd(15 * std::numbers::pi / 180, Vec3::UnitX()));
  CrazyfliePidController e(gains, xFrame(), crazyflieRotors());
  e.step(0, 0, tilted, speeds);
  CHECK(e.desiredAttitude()[2] == 36000);
  // falling at 1 m/s on the set-point: thrust up by 25 x 1000 per m/s (and the integral's first step)
  Standing falling;
  falling.pose.position = falling.setpoint.position = Vec3(0, 0, 1);
  falling.velocity = Vec3(0, 0, -1);
  CrazyfliePidController f(gains, xFrame(), crazyflieRotors());
  f.step(0, 0, falling, speeds);
  CHECK(f.desiredAttitude()[2] == Approx(36000 + 1000 * (25 * 1 + 15 * 0.01)));
}

TEST_CASE("crazyflie_pid: the mixer rolls with the left motors, the PWMs are capped together after the battery's "
          "compensation, giving up collective thrust first",
          "[quadrotor][crazyflie]") {
  CrazyfliePidGains gains;
  gains.thrust_base = 65000;  // near the command's ceiling
  gains.gyro_cutoff_hz = 0;    // the rates as they are (the filter would take the first sample's edge off)
  Standing in;
  in.pose.position = in.setpoint.position = Vec3(0, 0, 1);
  in.rates = Vec3(-0.5, 0, 0);  // rolling right at 0.5 rad/s: the rate loop asks for positive roll torque
  CrazyfliePidController c(gains, xFrame(), crazyflieRotors());
  std::array<double, 4> speeds{};
  c.step(0, 0, in, speeds);
  const auto m = c.motorCommands();
  CHECK(m[2] == Approx(m[3]));  // left pair alike
  CHECK(m[0] == Approx(m[1]));  // right pair alike
  CHECK(m[3] > m[0]);           // more on the left
  // the mixer's sums are not capped (the firmware's motorThrustUncapped): half the rate loop's output each side
  const double roll = 250 * (0.5 * 180 / std::numbers::pi) + 500 * (0.5 * 180 / std::numbers::pi) * 0.002;
  CHECK(m[3] - m[0] == Approx(2 * std::trunc(std::min(roll, 32767.0) / 2)));
  CHECK(m[3] > 65535);
  const CrazyflieThrustCurve curve = CrazyflieThrustCurve::propellers21plus();
  // a full battery (4.2 V) gives a motor more than 0.12 N (thrust(4.2 V) = 0.28 N): every motor as asked
  auto t = c.motorThrusts();
  for (std::size_t i = 0; i < 4; ++i) CHECK(t[i] == Approx(m[i] / 65535 * 0.12).epsilon(1e-12));
  // at 3.0 V the battery gives 0.113 N a motor: the left motors' PWM would pass 65535, and the excess
  // is taken from all four PWMs
  c.setBatteryVoltage(3.0);
  t = c.motorThrusts();
  const double left = curve.uncappedPwm(m[3], 3.0), right = curve.uncappedPwm(m[0], 3.0);
  REQUIRE(left > 65535);
  CHECK(t[3] == Approx(curve.thrust(3.0)).epsilon(1e-12));  // at full PWM
  CHECK(t[2] == Approx(t[3]));
  CHECK(t[0] == Approx(curve.thrust((right - (left - 65535)) / 65535 * 3.0)).epsilon(1e-12));
  CHECK(t[0] < m[0] / 65535 * 0.12);  // the collective given up, the differential kept in PWM
  // what a command-space cap (65535 before the compensation) cannot do, and NanoBench's flights show
  // (a motor at full PWM at 3.26 V logged): a command that reaches full PWM above 3.08 V
  CHECK(curve.uncappedPwm(65535, 3.26) < 65535);
  CHECK(curve.uncappedPwm(75400, 3.26) > 65535);
}

TEST_CASE("crazyflie_pid: a saved state continues identically, velocity commands", "[quadrotor][crazyflie]") {
  const CrazyfliePidGains gains;
  Standing in;
  in.pose.position = Vec3(0.3, -0.2, 0.9);
  in.setpoint.position = Vec3(0, 0, 1);
  in.velocity = Vec3(0.1, 0, 0);
  in.rates = Vec3(0.05, -0.02, 0.01);
  CrazyfliePidController a(gains, xFrame(), crazyflieRotors()), b(gains, xFrame(), crazyflieRotors());
  std::array<double, 4> sa{}, sb{};
  for (int i = 0; i < 7; ++i) a.step(i, i * 0.002, in, sa);
  std::vector<std::byte> saved;
  StateWriter out(saved);
  a.saveState(out);
  StateReader back(saved);
  b.loadState(back);
  for (int i = 7; i < 20; ++i) {
    a.step(i, i * 0.002, in, sa);
    b.step(i, i * 0.002, in, sb);
    CHECK(sa == sb);
  }
  CHECK(a.accepts(CommandLevel::Velocity));
  CHECK(a.accepts(CommandLevel::Attitude));
  CHECK(a.accepts(CommandLevel::Rates));
  CHECK(a.accepts(CommandLevel::Rotors));
  CHECK_FALSE(a.accepts(CommandLevel::Wheels));
  a.setCommand(Command::velocityYawRate(Vec3(0.5, 0, 0), 0), in.pose.position);
  a.step(20, 0.04, in, sa);
  CHECK(a.desiredVelocity().x() == Approx(0.5));
  CHECK(a.command().level == CommandLevel::Velocity);
  CHECK_THROWS_AS(CrazyfliePidController(gains, {{Vec3(0.046, 0, 0), 1}, {Vec3(0, 0.046, 0), -1}, {Vec3(-0.046, 0, 0), 1},
                                                 {Vec3(0, -0.046, 0), -1}}, crazyflieRotors()),
                  std::invalid_argument);  // a plus frame
}

namespace {

// a rigid Crazyflie (29 g, Förster's inertia, an X of 46 mm arms, first-order motors of 65 ms) under
// the controller at 500 Hz, integrated in 0.5 ms steps: the controller's loops closed on a vehicle
struct Flight : FlightInputs {
  double mass = 0.029;
  Vec3 inertia{16.57e-6, 16.66e-6, 29.26e-6};
  std::vector<Rotor> rotors = xFrame();
  RotorParams rotor = crazyflieRotors();
  double torque_ratio = 6.99e-3, motor_tau = 0.065;
  Pose pose;
  Vec3 velocity = Vec3::Zero(), rates = Vec3::Zero();  // world, body
  std::array<double, 4> speeds{}, commanded{};
  std::function<Setpoint(double)> path;
  CrazyfliePidController controller{CrazyfliePidGains{}, rotors, rotor};

  Setpoint reference(double t, double) override { return path(t); }
  bool holdsHeading() const override { return true; }
  void position(Pose& p, Vec3& v) const override { p = pose, v = velocity; }
  Vec3 bodyRates() const override { return rates; }

  // flies to `until` s from `t`; calls `each(t)` after every controller step
  template <class Each>
  double fly(double t, double until, std::int64_t& run, Each each) {
    const double dt = 0.0005;
    while (t < until - 1e-9) {
      if (std::llround(t / dt) % 4 == 0) {
        controller.step(run++, t, *this, commanded);
        each(t);
      }
      Vec3 force = Vec3::Zero(), torque = Vec3::Zero();
      for (std::size_t i = 0; i < 4; ++i) {
        speeds[i] += (commanded[i] - speeds[i]) * (1 - std::exp(-dt / motor_tau));
        const double f = rotor.thrust_coefficient * speeds[i] * speeds[i];
        force.z() += f;
        torque += rotors[i].position.cross(Vec3(0, 0, f)) + Vec3(0, 0, -rotors[i].direction * torque_ratio * f);
      }
      const Vec3 acceleration = pose.orientation * force / mass - Vec3(0, 0, 9.81);
      const Vec3 angular = (torque - rates.cross(inertia.asDiagonal() * rates)).cwiseQuotient(inertia);
      velocity += acceleration * dt;
      pose.position += velocity * dt;
      rates += angular * dt;
      const Vec3 turn = rates * dt;
      if (turn.norm() > 0) pose.orientation = (pose.orientation * Quat(Eigen::AngleAxisd(turn.norm(), turn.normalized()))).normalized();
      t += dt;
    }
    return t;
  }
};

}  // namespace

TEST_CASE("crazyflie_pid: closed on a rigid Crazyflie it hovers, and follows a moving set-point half a second late",
          "[quadrotor][crazyflie]") {
  Flight f;
  f.pose.position = Vec3(0, 0, 1);
  f.path = [](double) {
    Setpoint s;
    s.position = Vec3(0, 0, 1);
    return s;
  };
  // hover needs 29 g of thrust, the base gives 36000 / 65535 x 4 x 0.12 N = 26.9 g: the vz integral makes up the rest
  std::int64_t run = 0;
  double t = f.fly(0, 6, run, [](double) {});
  CHECK((f.pose.position - Vec3(0, 0, 1)).norm() < 0.01);
  CHECK(f.controller.desiredAttitude()[2] == Approx(0.029 * 9.81 / 4 / 0.12 * 65535).epsilon(0.01));
  // the set-point moves at 0.5 m/s along a diagonal (both the roll and the pitch loop at work): the
  // P-only position loop (2 /s, no feed-forward) follows it 1/kp = 0.5 s late, 0.25 m behind; the
  // tilt stays within 20 degrees
  const double start = t;
  const Vec3 along(0.6, 0.8, 0);
  f.path = [start, along](double now) {
    Setpoint s;
    s.position = Vec3(0, 0, 1) + along * 0.5 * std::max(0.0, now - start);
    return s;
  };
  double max_tilt = 0;
  t = f.fly(t, t + 8, run, [&](double) {
    max_tilt = std::max({max_tilt, std::abs(f.controller.desiredAttitude()[0]), std::abs(f.controller.desiredAttitude()[1])});
  });
  const Vec3 gap = Vec3(0, 0, 1) + along * 0.5 * (t - start) - f.pose.position;
  const double behind = gap.dot(along), aside = (gap - along * behind).norm();
  INFO("0.5 m/s: " << behind << " m behind, " << aside << " m aside, the velocity " << f.velocity.transpose()
                   << " m/s, tilt at most " << max_tilt);
  CHECK(behind == Approx(0.25).margin(0.03));
  CHECK(aside < 0.02);
  CHECK(f.velocity.dot(along) == Approx(0.5).margin(0.02));
  CHECK(max_tilt <= 20);
}

TEST_CASE("crazyflie_pid: attitude and body-rate commands fly the rigid Crazyflie, and survive a saved state",
          "[quadrotor][crazyflie]") {
  const double weight = 0.029 * 9.81;
  Flight f;
  f.pose.position = Vec3(0, 0, 1);
  f.path = [](double) { return Setpoint{}; };
  std::int64_t run = 0;
  // level, with the weight's thrust: it neither climbs nor sinks fast, nor drifts
  f.controller.setCommand(Command::attitude(0, 0, 0, weight), f.pose.position);
  f.speeds.fill(std::sqrt(weight / 4 / f.rotor.thrust_coefficient));  // the motors spinning for hover already
  double t = f.fly(0, 1, run, [](double) {});
  INFO("velocity " << f.velocity.transpose());
  CHECK(std::abs(f.velocity.z()) < 0.05);
  CHECK(Vec3(f.velocity.x(), f.velocity.y(), 0).norm() < 0.02);
  CHECK(f.controller.command().level == CommandLevel::Attitude);
  CHECK(f.controller.command().thrust == Approx(weight));
  // pitched 0.1 rad (ssx's signs: towards +x) with the thrust that keeps its height: it
  // accelerates along +x at about g tan(0.1), and holds the pitch asked for
  f.controller.setCommand(Command::attitude(0, 0.1, 0, weight / std::cos(0.1)), f.pose.position);
  const double vx = f.velocity.x();
  t = f.fly(t, t + 1, run, [](double) {});
  CHECK(f.velocity.x() - vx == Approx(9.81 * std::tan(0.1)).epsilon(0.25));
  const double pitch = std::asin(2 * (f.pose.orientation.w() * f.pose.orientation.y() -
                                      f.pose.orientation.z() * f.pose.orientation.x()));
  CHECK(pitch == Approx(0.1).margin(0.01));
  // a roll rate of 1 rad/s: the rate loop alone makes the body turn at it
  f.controller.setCommand(Command::rates(Vec3(1, 0, 0), weight), f.pose.position);
  t = f.fly(t, t + 0.3, run, [](double) {});
  CHECK(f.rates.x() == Approx(1).margin(0.1));
  CHECK(std::abs(f.rates.y()) < 0.1);
  CHECK(f.controller.command().body_rates.x() == 1);
  // the rates level is in a saved state: a copy goes on identically
  const CrazyfliePidGains gains;
  CrazyfliePidController copy(gains, xFrame(), crazyflieRotors());
  std::vector<std::byte> saved;
  StateWriter out(saved);
  f.controller.saveState(out);
  StateReader back(saved);
  copy.loadState(back);
  CHECK(copy.command().level == CommandLevel::Rates);
  std::array<double, 4> a{}, b{};
  f.controller.step(run, t, f, a);
  copy.step(run, t, f, b);
  CHECK(a == b);
}

TEST_CASE("crazyflie_pid: rotor speeds go to the motors as asked, the loops resting, and survive a saved state",
          "[quadrotor][crazyflie]") {
  const CrazyfliePidGains gains;
  Standing in;
  in.pose.position = Vec3(0, 0, 1);
  in.rates = Vec3(0.3, -0.2, 0.1);  // turning: the rate loop would answer it
  CrazyfliePidController a(gains, xFrame(), crazyflieRotors()), b(gains, xFrame(), crazyflieRotors());
  std::array<double, 4> sa{}, sb{};
  a.setCommand(Command::rotors({1500, 1600, 1700, 1800}), in.pose.position);
  for (int i = 0; i < 5; ++i) a.step(i, i * 0.002, in, sa);
  CHECK(sa == std::array<double, 4>{1500, 1600, 1700, 1800});
  CHECK(a.command().level == CommandLevel::Rotors);
  CHECK(a.command().rotor_speeds == std::vector<double>{1500, 1600, 1700, 1800});
  std::vector<std::byte> saved;
  StateWriter out(saved);
  a.saveState(out);
  StateReader back(saved);
  b.loadState(back);
  CHECK(back.done());
  b.step(5, 0.01, in, sb);
  CHECK(sb == sa);
  // back to attitude: the loops take over again
  a.setCommand(Command::attitude(0, 0, 0, 0.029 * 9.81), in.pose.position);
  a.step(6, 0.012, in, sa);
  CHECK(sa != std::array<double, 4>{1500, 1600, 1700, 1800});
}
