// The poses of a body measured outside the simulation: the pose used at a simulated time is the
// interpolation of the samples around it (position linear, orientation slerp) within 1 mm and
// 1 mrad; past the newest it is extrapolated for at most the horizon, then held; it is lost after
// the timeout; samples may come out of order; saved and loaded bitwise; bad samples refused.
#include <ssx/pose_stream.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace ssx;

namespace {

// a body on a circle of 1 m at 1 rad/s, turning with it
Pose onCircle(double t) {
  Pose p;
  p.position = Vec3(std::cos(t), std::sin(t), 1.0);
  p.orientation = Quat(Eigen::AngleAxisd(t + std::numbers::pi / 2, Vec3::UnitZ()));
  return p;
}

double angleBetween(const Quat& a, const Quat& b) { return a.angularDistance(b); }

}  // namespace

TEST_CASE("pose stream: between samples, the interpolation of the two around the time", "[pose_stream]") {
  PoseStream s;
  CHECK_FALSE(s.at(0.0).has_value());
  for (int k = 0; k <= 50; ++k) s.add(0.01 * k, onCircle(0.01 * k));  // motion capture at 100 Hz
  double worst = 0, worst_angle = 0;
  for (int k = 0; k < 250; ++k) {  // the simulation at 500 Hz
    const double t = 0.002 * k;
    const auto e = s.at(t);
    REQUIRE(e.has_value());
    CHECK_FALSE(e->extrapolated);
    CHECK_FALSE(e->lost);
    // the linear interpolation of the samples, computed here
    const double a = std::floor(t / 0.01 + 1e-9) * 0.01, u = (t - a) / 0.01;
    const Vec3 expected = onCircle(a).position + u * (onCircle(a + 0.01).position - onCircle(a).position);
    worst = std::max(worst, (e->pose.position - expected).norm());
    worst_angle = std::max(worst_angle, angleBetween(e->pose.orientation, onCircle(t).orientation));
    CHECK(e->age == Approx(t - a).margin(1e-9));
  }
  CHECK(worst < 1e-3);
  CHECK(worst_angle < 1e-3);
  // the velocity between the samples: 1 m/s along the circle, 1 rad/s about z
  const auto mid = s.at(0.255);
  CHECK(mid->linear_velocity.norm() == Approx(1.0).epsilon(1e-3));
  CHECK(mid->angular_velocity.z() == Approx(1.0).epsilon(1e-6));
}

TEST_CASE("pose stream: past the newest, extrapolated for the horizon, then held, then lost", "[pose_stream]") {
  PoseStream::Settings settings;
  settings.horizon = 0.05;
  settings.timeout = 0.2;
  PoseStream s(settings);
  for (int k = 0; k <= 10; ++k) s.add(0.01 * k, {Vec3(0.5 * 0.01 * k, 0, 1), Quat::Identity()});  // 0.5 m/s along x
  const auto near = s.at(0.13);
  CHECK(near->extrapolated);
  CHECK(near->pose.position.x() == Approx(0.05 + 0.5 * 0.03).margin(1e-12));
  CHECK(near->linear_velocity.x() == Approx(0.5));
  const auto held = s.at(0.25);  // 0.15 s past: held at the horizon
  CHECK(held->pose.position.x() == Approx(0.05 + 0.5 * 0.05).margin(1e-12));
  CHECK(held->linear_velocity.isZero());
  CHECK_FALSE(held->lost);
  CHECK(held->age == Approx(0.15));
  CHECK(s.at(0.31)->lost);
  // a new sample finds it again
  s.add(0.32, {Vec3(0.2, 0, 1), Quat::Identity()});
  CHECK_FALSE(s.at(0.32)->lost);
}

TEST_CASE("pose stream: out-of-order and repeated stamps, capacity, refusals, save and load", "[pose_stream]") {
  PoseStream::Settings settings;
  settings.capacity = 4;
  PoseStream s(settings);
  s.add(0.02, {Vec3(2, 0, 0), Quat::Identity()});
  s.add(0.00, {Vec3(0, 0, 0), Quat::Identity()});
  s.add(0.01, {Vec3(9, 0, 0), Quat::Identity()});
  s.add(0.01, {Vec3(1, 0, 0), Quat::Identity()});  // replaces
  CHECK(s.size() == 3);
  CHECK(s.at(0.015)->pose.position.x() == Approx(1.5));
  s.add(0.03, {Vec3(3, 0, 0), Quat::Identity()});
  s.add(0.04, {Vec3(4, 0, 0), Quat::Identity()});
  CHECK(s.size() == 4);  // the oldest went
  CHECK(s.at(0.0)->pose.position.x() == Approx(1.0));  // before the oldest kept: the oldest
  CHECK_THROWS_AS(s.add(NAN, Pose{}), std::invalid_argument);
  CHECK_THROWS_AS(s.add(0.05, {Vec3(NAN, 0, 0), Quat::Identity()}), std::invalid_argument);
  CHECK_THROWS_AS(s.add(0.05, {Vec3::Zero(), Quat(2, 0, 0, 0)}), std::invalid_argument);
  CHECK(s.size() == 4);
  CHECK_THROWS_AS(PoseStream({-1, 0.5, 64}), std::invalid_argument);

  std::vector<std::byte> saved;
  StateWriter w(saved);
  s.saveState(w);
  PoseStream back(settings);
  StateReader r(saved);
  back.loadState(r);
  for (double t : {0.005, 0.012, 0.033, 0.07, 1.0}) {
    const auto a = s.at(t), b = back.at(t);
    CHECK(a->pose.position == b->pose.position);
    CHECK(a->pose.orientation.coeffs() == b->pose.orientation.coeffs());
  }
  PoseStream small({0.05, 0.5, 2});
  StateReader again(saved);
  CHECK_THROWS_AS(small.loadState(again), StateError);
  CHECK(small.size() == 0);
}

TEST_CASE("pose stream: the ages of the poses used, summarised to 0.1 ms in bounded memory", "[pose_stream]") {
  AgeHistogram h;
  CHECK(h.summary().count == 0);
  CHECK(h.summary().p99 == 0);
  for (int i = 1; i <= 1000; ++i) h.add(i * 1e-3);
  AgeSummary s = h.summary();
  CHECK(s.count == 1000);
  CHECK(s.median == Approx(0.501).margin(1e-4));
  CHECK(s.p99 == Approx(0.991).margin(1e-4));
  CHECK(s.max == 1.0);
  // older than the histogram's reach: counted in the last bin, the maximum exact
  h.add(7.5);
  h.add(-1);  // counts as 0
  s = h.summary();
  CHECK(s.count == 1002);
  CHECK(s.max == 7.5);
  AgeHistogram one;
  one.add(0.00234);
  CHECK(one.summary().median == Approx(0.00234).margin(1e-4));
  CHECK(one.summary().median >= 0.00234);
}

TEST_CASE("pose stream: a sample stamped ahead is held until it is due, the age truthful, lost after the timeout",
          "[pose_stream]") {
  PoseStream s({0.05, 0.5, 64});
  s.add(0.0, onCircle(0.0));
  s.add(0.01, onCircle(0.01));
  s.add(100.0, onCircle(100.0));  // a hundred seconds ahead (a clock that is wrong, a hostile peer)
  // not moved towards it, and the age counts from the newest sample due
  const auto e = s.dueAt(0.2);
  REQUIRE(e);
  CHECK((e->pose.position - onCircle(0.01).position).norm() < 0.06);  // extrapolated 50 ms at most, then held
  CHECK(e->age == Approx(0.19));
  CHECK_FALSE(e->lost);
  const auto later = s.dueAt(1.0);
  REQUIRE(later);
  CHECK(later->lost);  // nothing due for more than the timeout
  CHECK(later->age == Approx(0.99));
  // when it is due, it is the pose
  const auto due = s.dueAt(100.0);
  REQUIRE(due);
  CHECK((due->pose.position - onCircle(100.0).position).norm() < 1e-12);
  CHECK_FALSE(due->lost);
  // only samples ahead: nothing yet
  PoseStream ahead;
  ahead.add(5.0, onCircle(5.0));
  CHECK_FALSE(ahead.dueAt(1.0).has_value());
  // a replay fed ahead of time, samples 10 ms apart: interpolated as at() does
  CHECK(s.dueAt(0.005)->pose.position == s.at(0.005)->pose.position);
}

TEST_CASE("pose stream: a position farther than 1e6 m is refused (a corrupted sample), nothing changed",
          "[pose_stream]") {
  PoseStream s;
  Pose p = onCircle(0.0);
  p.position.x() = 1e300;
  CHECK_THROWS_AS(s.add(0.0, p), std::invalid_argument);
  p.position.x() = 1e7;
  CHECK_THROWS_AS(s.add(0.0, p), std::invalid_argument);
  CHECK(s.size() == 0);
}
