// The Crazyflie firmware's Kalman filter: at rest it stays put; fed the exact IMU and positions of a
// vehicle accelerating on its thrust alone it follows the truth; with drag, which its in-flight
// prediction leaves out, its velocity reads high; fed a real flight's logged IMU and Vicon positions
// (NanoBench) it reproduces that flight's onboard estimate better than Vicon's velocity does; a
// saved and restored filter goes on with the same bits.
#include "crazyflie_kalman.hpp"
#include "nanobench_flight.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

using ssx::Quat;
using ssx::Vec3;
using ssx::quadrotor::CrazyflieKalman;

namespace {

constexpr double kG = 9.81;

// one run of the filter as the controller drives it at 100 Hz: a sample, the prediction, noise, a position
void run(CrazyflieKalman& f, const Vec3& acc, const Vec3& gyro, const Vec3& position, bool flying, double dt = 0.01) {
  f.addImu(acc, gyro);
  f.predict(dt, flying);
  f.addProcessNoise(dt);
  f.updatePosition(position);
  f.finalize();
}

// roll and pitch (rad) of an orientation
Vec3 tilt(const Quat& q) {
  const Vec3 z = q * Vec3::UnitZ();
  return {std::asin(-z.y()), std::asin(z.x()), 0};
}

// One series per axis: x, y and the rows to use.
struct Series {
  std::vector<double> x, y;
  std::vector<bool> use;
};

// y = k x + b over the rows in use of every axis, at the shift of y against x (rows, within +-10)
// that fits best: k
double gain(const std::vector<Series>& axes) {
  double best_r2 = -1, best_k = 0;
  for (int s = -10; s <= 10; ++s) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    for (const Series& a : axes)
      for (std::size_t i = 10; i + 10 < a.x.size(); ++i) {
        const auto j = static_cast<std::size_t>(static_cast<long>(i) + s);
        if (!a.use[j]) continue;
        n += 1, sx += a.x[i], sy += a.y[j], sxx += a.x[i] * a.x[i], sxy += a.x[i] * a.y[j], syy += a.y[j] * a.y[j];
      }
    const double cxx = sxx - sx * sx / n, cxy = sxy - sx * sy / n, cyy = syy - sy * sy / n;
    const double r2 = cxy * cxy / (cxx * cyy);
    if (r2 > best_r2) best_r2 = r2, best_k = cxy / cxx;
  }
  return best_k;
}

// A real flight flown through this filter: its logged IMU and Vicon positions at the log's 100 Hz,
// flying while the motors run. The gains of its horizontal velocity and of the onboard EKF's on
// Vicon's (x and y together), and the distance from the onboard position estimate (rms, m).
struct Refiltered {
  double mine = 0, logged = 0, position_rms = 0;
};

Refiltered refilter(const std::string& flight) {
  const auto f = ssx::test::readNanobenchFlight(flight);
  const auto& t = f.at("t");
  CrazyflieKalman k;
  k.reset(Vec3(f.at("px")[0], f.at("py")[0], f.at("pz")[0]), f.at("yaw")[0]);
  std::vector<Series> mine(2), logged(2);
  double squares = 0;
  int airborne = 0;
  for (std::size_t i = 1; i < t.size(); ++i) {
    const Vec3 acc = kG * Vec3(f.at("acc_x_g")[i], f.at("acc_y_g")[i], f.at("acc_z_g")[i]);
    const Vec3 gyro(f.at("gyro_x")[i], f.at("gyro_y")[i], f.at("gyro_z")[i]);
    run(k, acc, gyro, Vec3(f.at("px")[i], f.at("py")[i], f.at("pz")[i]), f.at("m1")[i] > 0, t[i] - t[i - 1]);
    for (int axis = 0; axis < 2; ++axis) {
      const double vicon = f.at(axis == 0 ? "vx" : "vy")[i];
      const bool use = f.at("pz")[i] > 0.5;
      mine[axis].x.push_back(vicon), mine[axis].y.push_back(k.velocity()[axis]), mine[axis].use.push_back(use);
      logged[axis].x.push_back(vicon), logged[axis].y.push_back(f.at(axis == 0 ? "est_vx" : "est_vy")[i]);
      logged[axis].use.push_back(use);
    }
    if (f.at("pz")[i] > 0.5) {
      squares += (k.position().head<2>() - Eigen::Vector2d(f.at("est_x")[i], f.at("est_y")[i])).squaredNorm();
      ++airborne;
    }
  }
  REQUIRE(airborne > 1000);
  return {gain(mine), gain(logged), std::sqrt(squares / airborne)};
}

}  // namespace

TEST_CASE("crazyflie kalman: at rest on the ground it stays where it was put, level and still") {
  CrazyflieKalman f;
  f.reset(Vec3(1, 2, 0.05), 0.3);
  for (int i = 0; i < 500; ++i) run(f, Vec3(0, 0, kG), Vec3::Zero(), Vec3(1, 2, 0.05), false);
  CHECK((f.position() - Vec3(1, 2, 0.05)).norm() < 1e-6);
  CHECK(f.velocity().norm() < 1e-6);
  CHECK(tilt(f.attitude()).norm() < 1e-6);
  CHECK(std::abs(f.attitude().toRotationMatrix().eulerAngles(2, 1, 0)[0] - 0.3) < 1e-6);
}

TEST_CASE("crazyflie kalman: on its thrust alone, tilted and accelerating, it follows the truth") {
  // tilted 10 degrees about y from rest at hover: thrust g / cos along the body z, the world's
  // acceleration g tan horizontally; exact IMU and positions
  const double theta = 10 * M_PI / 180;
  CrazyflieKalman f;
  f.reset(Vec3(0, 0, 1), 0);
  // level hover first, to settle
  for (int i = 0; i < 200; ++i) run(f, Vec3(0, 0, kG), Vec3::Zero(), Vec3(0, 0, 1), true);
  // then a rotation to the tilt over 0.1 s, and 2 s of acceleration
  Vec3 x(0, 0, 1), v = Vec3::Zero();
  double angle = 0;
  const double dt = 0.01;
  for (int i = 0; i < 210; ++i) {
    const double rate = i < 10 ? theta / 0.1 : 0.0;
    angle += rate * dt;
    const Vec3 acc(0, 0, kG / std::cos(angle));
    const Vec3 a_world(kG * std::tan(angle), 0, 0);
    x += v * dt + a_world * dt * dt / 2;
    v += a_world * dt;
    run(f, acc, Vec3(0, rate, 0), x, true);
  }
  CHECK((f.position() - x).norm() < 0.002);
  CHECK((f.velocity() - v).norm() < 0.02);
  CHECK(std::abs(tilt(f.attitude()).y() - theta) < 0.5 * M_PI / 180);
}

TEST_CASE("crazyflie kalman: with drag its in-flight prediction leaves out, its velocity reads high") {
  // a steady forward flight: tilted so that the thrust's horizontal part balances a drag of c v, at
  // constant speed; the accelerometer reads the drag along the body x, which the filter ignores in flight
  const double c = 0.4, speed = 1.0;
  const double theta = std::atan(c * speed / kG);
  const Quat q(Eigen::AngleAxisd(theta, Vec3::UnitY()));
  CrazyflieKalman f;
  f.reset(Vec3(0, 0, 1), 0);
  const double dt = 0.01;
  Vec3 x(0, 0, 1);
  // (the filter starts level and at rest: the first seconds settle it)
  for (int i = 0; i < 1000; ++i) {
    x += Vec3(speed, 0, 0) * dt;
    const Vec3 specific_world(-c * speed, 0, kG);  // thrust plus drag, per unit mass, minus nothing else
    run(f, q.conjugate() * specific_world, Vec3::Zero(), x, true);
  }
  const double read = f.velocity().x();
  INFO("estimated " << read << " m/s at a true " << speed << " m/s");
  CHECK(read > speed * 1.005);
  CHECK(read < speed * 1.2);
}

TEST_CASE(
    "crazyflie kalman: real flights' logged IMU and Vicon give the onboard estimate's position, and its "
    "velocity on the fast flights") {
  // the three fast flights that lag most: the onboard EKF read their velocity 3-7 % high; so does
  // this filter, within 0.06 (0.049 on the fast eight rep 2), and its position stays within 8 cm
  // (rms) of the onboard one
  for (const char* flight : {"B7_oval_fast_rep1", "B3_figure8_fast_rep2", "B9_trefoil_fast_rep1"}) {
    const Refiltered r = refilter(flight);
    INFO(flight << ": velocity / Vicon's " << r.mine << " (onboard " << r.logged << "), position " << r.position_rms
                << " m rms from the onboard one");
    CHECK(r.logged > 1.02);
    CHECK(r.mine > 1.0);
    CHECK(std::abs(r.mine - r.logged) < 0.06);
    CHECK(r.position_rms < 0.08);
  }
  // the slow circle: the onboard EKF read its velocity 9 % low, this filter reads it 8 % high (not
  // explained: docs/crazyflie-fidelity.md); the positions agree as well
  const Refiltered slow = refilter("B2_circle_slow_rep1");
  INFO("slow circle: velocity / Vicon's " << slow.mine << " (onboard " << slow.logged << "), position "
                                          << slow.position_rms << " m rms");
  CHECK(slow.logged < 0.95);
  CHECK(slow.mine > 1.05);
  CHECK(slow.position_rms < 0.03);
}

TEST_CASE("crazyflie kalman: saved and restored, it goes on with the same bits") {
  CrazyflieKalman a;
  a.reset(Vec3(0, 0, 1), 0.1);
  for (int i = 0; i < 50; ++i) run(a, Vec3(0.3, -0.1, kG), Vec3(0.01, 0.02, -0.01), Vec3(0.001 * i, 0, 1), true);
  a.addImu(Vec3(0.1, 0, kG), Vec3(0, 0.1, 0));  // a sample waiting for the next prediction
  std::vector<std::byte> saved;
  ssx::StateWriter out(saved);
  a.save(out);
  CrazyflieKalman b;
  ssx::StateReader in(saved);
  b.load(in);
  for (CrazyflieKalman* f : {&a, &b})
    for (int i = 0; i < 20; ++i)
      run(*f, Vec3(0.2, 0.1, kG), Vec3(0.03, 0, 0.01), Vec3(0.05 + 0.002 * i, 0.01, 1), true);
  CHECK(a.position() == b.position());
  CHECK(a.velocity() == b.velocity());
  CHECK(a.attitude().coeffs() == b.attitude().coeffs());
  CHECK(a.variances() == b.variances());
}
