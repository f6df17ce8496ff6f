// The ROS bridges' shared transport: what a step stages goes out in order on the publishing thread
// only after commit, flush waits for it, a robot without an IMU publishes none; what arrives is
// each robot's newest, in the order it came, with the round trip from the odometry it answers;
// lock-step's waits say who is missing. A ghost's poses are all kept, in arrival order, at most
// 1,024 queued per robot; a range's points and an operator's force go out with their message,
// however commits interleave with sending; a joystick's state is kept, bounded.
#include "transport.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>

using namespace ssx::bridge;

namespace {

const std::function<bool()> kNever = [] { return false; };

class Recording final : public Transport {
 public:
  explicit Recording(std::vector<RobotTopics> robots) : Transport(std::move(robots)) { startPublishing(); }
  ~Recording() override { stopPublishing(); }
  std::vector<Outgoing> sent() const {
    std::lock_guard<std::mutex> lock(mutex);
    return messages;
  }
  std::thread::id sender;
  std::atomic<bool> peer{false};
  using Transport::receivedSetpoint;
  using Transport::receivedVelocity;
  using Transport::receivedPose;
  using Transport::receivedJoy;
  std::vector<std::vector<std::array<double, 3>>> points;  // each range's, copied as it is sent
  std::vector<std::vector<std::uint8_t>> images;            // each image's bytes, likewise
  std::vector<std::vector<double>> values;                  // each transforms' or joint states' values

 private:
  void send(const Outgoing& m) override {
    std::lock_guard<std::mutex> lock(mutex);
    sender = std::this_thread::get_id();
    messages.push_back(m);
    if (m.kind == Outgoing::Kind::Range) points.emplace_back(m.points, m.points + m.count);
    if (m.kind == Outgoing::Kind::Image) images.emplace_back(m.bytes, m.bytes + m.count);
    if (m.kind == Outgoing::Kind::Transforms || m.kind == Outgoing::Kind::JointStates || m.kind == Outgoing::Kind::Scan)
      values.emplace_back(m.values, m.values + m.count);
  }
  bool connected(std::size_t) const override { return peer; }
  mutable std::mutex mutex;
  std::vector<Outgoing> messages;
};

RobotTopics topics(const std::string& name, bool imu, bool setpoint, bool velocity) {
  RobotTopics t;
  t.name = name;
  t.imu = imu;
  t.setpoint = setpoint;
  t.velocity = velocity;
  return t;
}

std::vector<RobotTopics> twoRobots() { return {topics("a", true, true, true), topics("b", false, true, false)}; }

}  // namespace

TEST_CASE("bridge transport: staged messages go out in order, on its own thread, after commit", "[bridge]") {
  Recording t(twoRobots());
  Odometry o;
  o.time = 0.5;
  t.publishClock(0.5);
  t.publishOdometry(1, o);
  t.publishImu(0, Imu{});
  t.publishImu(1, Imu{});  // b has no IMU topic: dropped
  t.flush();
  const auto sent = t.sent();
  REQUIRE(sent.size() == 3);
  CHECK(sent[0].kind == Outgoing::Kind::Clock);
  CHECK(sent[0].time == 0.5);
  CHECK(sent[1].kind == Outgoing::Kind::Odometry);
  CHECK(sent[1].robot == 1);
  CHECK(sent[2].kind == Outgoing::Kind::Imu);
  CHECK(sent[2].robot == 0);
  CHECK(t.sender != std::this_thread::get_id());
  // staged but not committed: nothing more goes out, even on flush's commit only
  t.publishClock(1.0);
  CHECK(t.sent().size() == 3);
  t.stopPublishing();  // sends what was staged first
  CHECK(t.sent().size() == 4);
}

TEST_CASE("bridge transport: what arrives, in order, with its round trip, lock-step's waits", "[bridge]") {
  Recording t(twoRobots());
  CHECK(t.latestSetpoint(0).count == 0);
  CHECK(t.waitForSetpoints(0.0, 0.01, kNever) == std::vector<std::string>{"a", "b"});
  CHECK(t.waitForPeers(0.01, kNever) == std::vector<std::string>{"a", "b"});
  t.peer = true;
  CHECK(t.waitForPeers(0.01, kNever).empty());

  Odometry o;
  o.time = 0.02;
  t.publishOdometry(0, o);
  t.flush();
  t.receivedVelocity(0, {1, 0, 0}, {0, 0, 0.5});
  t.receivedSetpoint(0, 0.02, {1, 2, 3}, {1, 0, 0, 0});
  const Setpoint s = t.latestSetpoint(0);
  const Velocity v = t.latestVelocity(0);
  CHECK(s.count == 1);
  CHECK(s.position == std::array<double, 3>{1, 2, 3});
  CHECK(v.count == 1);
  CHECK(v.angular[2] == 0.5);
  CHECK(v.order < s.order);  // the velocity came first
  CHECK(t.roundTrips().size() == 1);  // the set-point stamped 0.02 answered the odometry of 0.02
  // b has not answered yet: the wait names it, then returns as soon as it does
  CHECK(t.waitForSetpoints(0.02, 0.01, kNever) == std::vector<std::string>{"b"});
  std::thread answer([&] { t.receivedSetpoint(1, 0.02, {0, 0, 1}, {1, 0, 0, 0}); });
  CHECK(t.waitForSetpoints(0.02, 5.0, kNever).empty());
  answer.join();
  // an older stamp does not answer a newer odometry
  CHECK(t.waitForSetpoints(0.04, 0.01, kNever) == std::vector<std::string>{"a", "b"});
}

TEST_CASE("bridge transport: lock-step's waits end when the run is stopped (Ctrl-C), not at their timeout", "[bridge]") {
  Recording t(twoRobots());
  std::atomic<bool> stop{false};
  const std::function<bool()> stopped = [&] { return stop.load(); };
  for (int which = 0; which < 2; ++which) {
    INFO((which == 0 ? "waiting for set-points" : "waiting for peers"));
    stop = false;
    const auto began = std::chrono::steady_clock::now();
    std::thread ctrl_c([&] { stop = true; });
    // an hour's timeout: it returns once the flag is seen, naming who is still missing
    const auto missing = which == 0 ? t.waitForSetpoints(0.02, 3600, stopped) : t.waitForPeers(3600, stopped);
    ctrl_c.join();
    CHECK(missing == std::vector<std::string>{"a", "b"});
    CHECK(std::chrono::steady_clock::now() - began < std::chrono::seconds(60));
  }
}

TEST_CASE("bridge transport: a ghost's poses are all kept, in arrival order, bounded", "[bridge]") {
  std::vector<RobotTopics> robots = twoRobots();
  robots[1].ghost = true;
  Recording t(robots);
  const std::uint64_t before = t.received();
  t.receivedPose(1, 0.02, {1, 0, 0}, {1, 0, 0, 0});
  t.receivedPose(1, 0.01, {0, 0, 0}, {1, 0, 0, 0});  // late: kept, in the order it came
  CHECK(t.received() == before + 2);
  std::vector<PoseSample> got;
  t.takePoses(got);
  REQUIRE(got.size() == 2);
  CHECK(got[0].stamp == 0.02);
  CHECK(got[1].stamp == 0.01);
  t.takePoses(got);
  CHECK(got.empty());
  // lock-step waits for a ghost's pose as for a set-point
  t.receivedSetpoint(0, 0.04, {0, 0, 0}, {1, 0, 0, 0});
  t.receivedSetpoint(1, 0.04, {0, 0, 0}, {1, 0, 0, 0});
  CHECK(t.waitForSetpoints(0.04, 0.01, kNever) == std::vector<std::string>{"b"});
  t.receivedPose(1, 0.04, {0, 0, 0}, {1, 0, 0, 0});
  CHECK(t.waitForSetpoints(0.04, 0.01, kNever).empty());
  t.takePoses(got);
  // nobody takes them: at most 1,024 wait, the oldest dropped and counted (from another thread)
  std::thread flood([&] {
    for (int k = 0; k < 1100; ++k) t.receivedPose(1, 1.0 + k * 0.01, {0, 0, 0}, {1, 0, 0, 0});
  });
  flood.join();
  t.takePoses(got);
  CHECK(got.size() == Transport::kMaxPosesQueued);
  CHECK(got.front().stamp == Approx(1.0 + 76 * 0.01));
  CHECK(t.posesDropped() == 1100 - Transport::kMaxPosesQueued);
}

TEST_CASE("bridge transport: a range's points, an image's bytes and an operator's force go out with their message",
          "[bridge]") {
  std::vector<RobotTopics> robots = twoRobots();
  robots[0].range = true;
  robots[1].force = true;
  robots[1].image = true;
  Recording t(robots);
  // many steps committed while the thread sends: each range keeps its own points
  for (int k = 0; k < 200; ++k) {
    std::vector<std::array<double, 3>> points(static_cast<std::size_t>(k % 5), {double(k), 0, 0});
    t.publishRange(0, k, false, points);
    t.publishRange(1, k, false, points);  // b publishes no range: dropped
    t.publishForce(1, k, {0, double(k), 0});
    t.publishImage(1, k, 2, 1, 60.0, std::vector<std::uint8_t>(6, static_cast<std::uint8_t>(k)));
    t.publishImage(0, k, 2, 1, 60.0, std::vector<std::uint8_t>(6, 0));  // a has no image topic: dropped
    t.commit();
  }
  t.flush();
  const auto sent = t.sent();
  REQUIRE(sent.size() == 600);
  REQUIRE(t.points.size() == 200);
  REQUIRE(t.images.size() == 200);
  for (std::size_t k = 0; k < 200; ++k) {
    CHECK(t.points[k].size() == k % 5);
    for (const auto& p : t.points[k]) CHECK(p[0] == double(k));
    CHECK(sent[3 * k + 1].kind == Outgoing::Kind::Force);
    CHECK(sent[3 * k + 1].force[1] == double(k));
    CHECK(sent[3 * k + 2].width == 2);
    CHECK(t.images[k] == std::vector<std::uint8_t>(6, static_cast<std::uint8_t>(k)));
  }
  // a proximity ring's distances and readings, in pairs, for a robot that publishes a scan
  robots[0].scan = true;
  Recording s(robots);
  const std::vector<double> angles{0.5, -0.5}, distances{0.01, std::numeric_limits<double>::infinity()}, readings{0.8, 0.0};
  s.publishScan(0, 1.5, 0.05, 0.03, angles, distances, readings);
  s.publishScan(1, 1.5, 0.05, 0.03, angles, distances, readings);  // b has no scan: dropped
  s.flush();
  REQUIRE(s.sent().size() == 1);
  CHECK(s.sent()[0].kind == Outgoing::Kind::Scan);
  CHECK(s.sent()[0].time == 1.5);
  CHECK(s.values.at(0) == std::vector<double>{0.05, 0.03, 0.5, 0.01, 0.8, -0.5, std::numeric_limits<double>::infinity(), 0.0});
  CHECK(sent[2].fov_deg == 60.0);
  // a joystick's state: the newest, at most 64 axes and buttons
  std::vector<float> axes(100, 0.5f);
  std::vector<int> buttons(3, 1);
  t.receivedJoy(1, 0.5, axes.data(), axes.size(), buttons.data(), buttons.size());
  const Joy j = t.latestJoy(1);
  CHECK(j.count == 1);
  CHECK(j.stamp == 0.5);
  CHECK(j.axes.size() == 64);
  CHECK(j.buttons == std::vector<int>{1, 1, 1});
}

TEST_CASE("bridge transport: transforms and joint states go out with their values, only for robots that take /tf",
          "[bridge]") {
  std::vector<RobotTopics> robots = twoRobots();
  robots[0].tf = true;
  robots[0].joints = {"wheel"};
  Recording t(robots);
  // two commits (the second's values found after the first's whether the publishing thread took
  // the first batch already or both queued together), and the robot without /tf staging nothing
  t.publishTransforms(0, 0.02, {1, 2, 3, 1, 0, 0, 0, 4, 5, 6, 0, 1, 0, 0});
  t.publishJointStates(0, 0.02, {0.5, -1.5});
  t.publishTransforms(1, 0.02, {9, 9, 9, 1, 0, 0, 0});
  t.commit();
  t.publishJointStates(0, 0.04, {0.6, -1.4});
  t.commit();
  t.flush();
  const std::vector<Outgoing> sent = t.sent();
  REQUIRE(sent.size() == 3);
  CHECK(sent[0].kind == Outgoing::Kind::Transforms);
  CHECK(sent[1].kind == Outgoing::Kind::JointStates);
  CHECK(sent[2].time == 0.04);
  REQUIRE(t.values.size() == 3);
  CHECK(t.values[0] == std::vector<double>{1, 2, 3, 1, 0, 0, 0, 4, 5, 6, 0, 1, 0, 0});
  CHECK(t.values[1] == std::vector<double>{0.5, -1.5});
  CHECK(t.values[2] == std::vector<double>{0.6, -1.4});
}
