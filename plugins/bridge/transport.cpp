// The ROS bridges' shared transport logic (C++17). See transport.hpp.
#include "transport.hpp"

#include <cmath>

namespace ssx::bridge {

namespace {
// a stamp as whole nanoseconds: what survives the trip through a message's sec and nanosec fields
std::int64_t nanos(double seconds) { return std::llround(seconds * 1e9); }
}  // namespace

Transport::Transport(std::vector<RobotTopics> robots)
    : robots_(std::move(robots)), setpoints_(robots_.size()), velocities_(robots_.size()) {
  const std::size_t room = 4 * robots_.size() + 16;
  staged_.reserve(room);
  queue_.reserve(room);
  sending_.reserve(room);
}

Transport::~Transport() { stopPublishing(); }

void Transport::startPublishing() {
  if (publisher_.joinable()) return;
  publisher_ = std::thread([this] { publishLoop(); });
}

void Transport::publishClock(double time) {
  Outgoing m;
  m.kind = Outgoing::Kind::Clock;
  m.time = time;
  staged_.push_back(m);
}

void Transport::publishOdometry(std::size_t robot, const Odometry& odometry) {
  Outgoing m;
  m.kind = Outgoing::Kind::Odometry;
  m.robot = robot;
  m.odometry = odometry;
  staged_.push_back(m);
}

void Transport::publishImu(std::size_t robot, const Imu& imu) {
  if (!robots_.at(robot).imu) return;
  Outgoing m;
  m.kind = Outgoing::Kind::Imu;
  m.robot = robot;
  m.imu = imu;
  staged_.push_back(m);
}

void Transport::commit() {
  if (staged_.empty()) return;  // (most steps publish nothing: no lock, no wake-up)
  {
    // one lock per step, however many robots: the buffers trade places, so none is allocated
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (queue_.empty())
      queue_.swap(staged_);
    else
      queue_.insert(queue_.end(), staged_.begin(), staged_.end());
  }
  staged_.clear();
  queue_changed_.notify_all();
}

void Transport::publishLoop() {
  std::unique_lock<std::mutex> lock(queue_mutex_);
  for (;;) {
    queue_changed_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (queue_.empty() && stop_) return;
    sending_.swap(queue_);
    busy_ = true;
    lock.unlock();
    for (const Outgoing& m : sending_) {
      if (m.kind == Outgoing::Kind::Odometry && m.robot == 0) {  // the round trip starts when it leaves
        std::lock_guard<std::mutex> guard(mutex_);
        sent_[nanos(m.odometry.time)] = std::chrono::steady_clock::now();
        while (sent_.size() > 1000) sent_.erase(sent_.begin());
      }
      send(m);
    }
    sending_.clear();
    lock.lock();
    busy_ = false;
    queue_changed_.notify_all();  // (flush waits for this)
  }
}

void Transport::flush() {
  commit();
  if (!publisher_.joinable()) return;
  std::unique_lock<std::mutex> lock(queue_mutex_);
  queue_changed_.wait(lock, [&] { return queue_.empty() && !busy_; });
}

void Transport::stopPublishing() {
  if (!publisher_.joinable()) return;
  commit();
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stop_ = true;
  }
  queue_changed_.notify_all();
  publisher_.join();  // after sending what was queued
}

void Transport::receivedSetpoint(std::size_t robot, double stamp, const std::array<double, 3>& position,
                                 const std::array<double, 4>& orientation_wxyz) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Setpoint& s = setpoints_.at(robot);
    s.stamp = stamp;
    const auto sent = sent_.find(nanos(stamp));
    if (sent != sent_.end())
      round_trips_.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - sent->second).count());
    s.position = position;
    s.orientation = orientation_wxyz;
    ++s.count;
    s.order = ++received_;
    received_count_.store(received_, std::memory_order_release);
  }
  arrived_.notify_all();
}

void Transport::receivedVelocity(std::size_t robot, const std::array<double, 3>& linear,
                                 const std::array<double, 3>& angular) {
  std::lock_guard<std::mutex> lock(mutex_);
  Velocity& v = velocities_.at(robot);
  v.linear = linear;
  v.angular = angular;
  ++v.count;
  v.order = ++received_;
  received_count_.store(received_, std::memory_order_release);
}

Setpoint Transport::latestSetpoint(std::size_t robot) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return setpoints_.at(robot);
}

Velocity Transport::latestVelocity(std::size_t robot) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return velocities_.at(robot);
}

std::vector<std::string> Transport::missingSetpoints(double time) const {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < robots_.size(); ++i)
    if (robots_[i].setpoint && (setpoints_[i].count == 0 || setpoints_[i].stamp < time - 1e-9))
      names.push_back(robots_[i].name);
  return names;
}

std::vector<std::string> Transport::waitForSetpoints(double time, double timeout_s) const {
  std::unique_lock<std::mutex> lock(mutex_);
  arrived_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return missingSetpoints(time).empty(); });
  return missingSetpoints(time);
}

std::vector<std::string> Transport::waitForPeers(double timeout_s) const {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::vector<std::string> missing;
  for (;;) {
    missing.clear();
    for (std::size_t i = 0; i < robots_.size(); ++i)
      if (robots_[i].setpoint && !connected(i)) missing.push_back(robots_[i].name);
    if (missing.empty() || std::chrono::steady_clock::now() >= deadline) return missing;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::vector<double> Transport::roundTrips() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return round_trips_;
}

}  // namespace ssx::bridge
