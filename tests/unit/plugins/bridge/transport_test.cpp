// The ROS bridges' shared transport: what a step stages goes out in order on the publishing thread
// only after commit, flush waits for it, a robot without an IMU publishes none; what arrives is
// each robot's newest, in the order it came, with the round trip from the odometry it answers;
// lock-step's waits say who is missing.
#include "transport.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <mutex>
#include <thread>

using namespace ssx::bridge;

namespace {

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

 private:
  void send(const Outgoing& m) override {
    std::lock_guard<std::mutex> lock(mutex);
    sender = std::this_thread::get_id();
    messages.push_back(m);
  }
  bool connected(std::size_t) const override { return peer; }
  mutable std::mutex mutex;
  std::vector<Outgoing> messages;
};

std::vector<RobotTopics> twoRobots() { return {{"a", true, true, true}, {"b", false, true, false}}; }

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

TEST_CASE("bridge transport: what arrives, in order, with its round trip; lock-step's waits", "[bridge]") {
  Recording t(twoRobots());
  CHECK(t.latestSetpoint(0).count == 0);
  CHECK(t.waitForSetpoints(0.0, 0.01) == std::vector<std::string>{"a", "b"});
  CHECK(t.waitForPeers(0.01) == std::vector<std::string>{"a", "b"});
  t.peer = true;
  CHECK(t.waitForPeers(0.01).empty());

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
  CHECK(t.waitForSetpoints(0.02, 0.01) == std::vector<std::string>{"b"});
  std::thread answer([&] { t.receivedSetpoint(1, 0.02, {0, 0, 1}, {1, 0, 0, 0}); });
  CHECK(t.waitForSetpoints(0.02, 5.0).empty());
  answer.join();
  // an older stamp does not answer a newer odometry
  CHECK(t.waitForSetpoints(0.04, 0.01) == std::vector<std::string>{"a", "b"});
}
