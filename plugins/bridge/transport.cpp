// The ROS bridges' shared transport logic (C++17). See transport.hpp.
#include "transport.hpp"

#include <algorithm>
#include <cmath>

namespace ssx::bridge {

namespace {
// a stamp as whole nanoseconds: what survives the trip through a message's sec and nanosec fields
std::int64_t nanos(double seconds) { return std::llround(seconds * 1e9); }
}  // namespace

Transport::Transport(std::vector<RobotTopics> robots)
    : robots_(std::move(robots)),
      setpoints_(robots_.size()),
      velocities_(robots_.size()),
      joys_(robots_.size()),
      joint_commands_(robots_.size()),
      queued_(robots_.size(), 0),
      newest_pose_(robots_.size(), -1.0) {
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

void Transport::publishRange(std::size_t robot, double time, bool body_frame,
                             const std::vector<std::array<double, 3>>& points) {
  if (!robots_.at(robot).range) return;
  Outgoing m;
  m.kind = Outgoing::Kind::Range;
  m.robot = robot;
  m.time = time;
  m.body_frame = body_frame;
  m.first = staged_points_.size();
  m.count = points.size();
  staged_points_.insert(staged_points_.end(), points.begin(), points.end());
  staged_.push_back(m);
}

void Transport::publishForce(std::size_t robot, double time, const std::array<double, 3>& force) {
  if (!robots_.at(robot).force) return;
  Outgoing m;
  m.kind = Outgoing::Kind::Force;
  m.robot = robot;
  m.time = time;
  m.force = force;
  staged_.push_back(m);
}

void Transport::publishImage(std::size_t robot, double time, int width, int height, double fov_deg,
                             const std::vector<std::uint8_t>& rgb) {
  if (!robots_.at(robot).image) return;
  Outgoing m;
  m.kind = Outgoing::Kind::Image;
  m.robot = robot;
  m.time = time;
  m.width = width;
  m.height = height;
  m.fov_deg = fov_deg;
  m.first = staged_bytes_.size();
  m.count = rgb.size();
  staged_bytes_.insert(staged_bytes_.end(), rgb.begin(), rgb.end());
  staged_.push_back(m);
}

Outgoing& Transport::stageValues(Outgoing::Kind kind, std::size_t robot, double time, const std::vector<double>& values) {
  Outgoing m;
  m.kind = kind;
  m.robot = robot;
  m.time = time;
  m.first = staged_values_.size();
  m.count = values.size();
  staged_values_.insert(staged_values_.end(), values.begin(), values.end());
  staged_.push_back(m);
  return staged_.back();
}

void Transport::publishTransforms(std::size_t robot, double time, const std::vector<double>& poses) {
  if (robots_.at(robot).tf) stageValues(Outgoing::Kind::Transforms, robot, time, poses);
}

void Transport::publishJointStates(std::size_t robot, double time, const std::vector<double>& values) {
  if (robots_.at(robot).tf && !robots_[robot].joints.empty()) stageValues(Outgoing::Kind::JointStates, robot, time, values);
}

void Transport::publishScan(std::size_t robot, double time, double reach, double radius, const std::vector<double>& angles,
                            const std::vector<double>& distances, const std::vector<double>& readings) {
  if (!robots_.at(robot).scan) return;
  Outgoing m;
  m.kind = Outgoing::Kind::Scan;
  m.robot = robot;
  m.time = time;
  m.first = staged_values_.size();
  const std::size_t n = std::min({angles.size(), distances.size(), readings.size()});
  m.count = 2 + 3 * n;
  staged_values_.insert(staged_values_.end(), {reach, radius});
  for (std::size_t k = 0; k < n; ++k) staged_values_.insert(staged_values_.end(), {angles[k], distances[k], readings[k]});
  staged_.push_back(m);
}

void Transport::publishGround(std::size_t robot, double time, const std::vector<double>& values) {
  if (robots_.at(robot).ground) stageValues(Outgoing::Kind::Ground, robot, time, values);
}

void Transport::publishRangeBearing(std::size_t robot, double time, const std::vector<double>& values,
                                    const std::vector<std::uint8_t>& bytes) {
  if (!robots_.at(robot).range_bearing) return;
  stageValues(Outgoing::Kind::RangeBearing, robot, time, values).first_byte = staged_bytes_.size();
  staged_bytes_.insert(staged_bytes_.end(), bytes.begin(), bytes.end());
}

namespace {
bool holdsValues(Outgoing::Kind kind) {
  return kind == Outgoing::Kind::Transforms || kind == Outgoing::Kind::JointStates || kind == Outgoing::Kind::Scan ||
         kind == Outgoing::Kind::Ground || kind == Outgoing::Kind::RangeBearing;
}
}  // namespace

void Transport::commit() {
  if (staged_.empty()) return;  // (most steps publish nothing: no lock, no wake-up)
  {
    // one lock per step, however many robots: the buffers trade places, so none is allocated
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (queue_.empty()) {
      queue_.swap(staged_);
      queue_points_.swap(staged_points_);
      queue_bytes_.swap(staged_bytes_);
      queue_values_.swap(staged_values_);
    } else {
      const std::size_t points = queue_points_.size(), bytes = queue_bytes_.size(), values = queue_values_.size();
      for (Outgoing& m : staged_) {
        m.first += m.kind == Outgoing::Kind::Image ? bytes : holdsValues(m.kind) ? values : points;
        m.first_byte += bytes;
      }
      queue_.insert(queue_.end(), staged_.begin(), staged_.end());
      queue_points_.insert(queue_points_.end(), staged_points_.begin(), staged_points_.end());
      queue_bytes_.insert(queue_bytes_.end(), staged_bytes_.begin(), staged_bytes_.end());
      queue_values_.insert(queue_values_.end(), staged_values_.begin(), staged_values_.end());
    }
  }
  staged_.clear();
  staged_points_.clear();
  staged_bytes_.clear();
  staged_values_.clear();
  queue_changed_.notify_all();
}

void Transport::publishLoop() {
  std::unique_lock<std::mutex> lock(queue_mutex_);
  for (;;) {
    queue_changed_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (queue_.empty() && stop_) return;
    sending_.swap(queue_);
    sending_points_.swap(queue_points_);
    sending_bytes_.swap(queue_bytes_);
    sending_values_.swap(queue_values_);
    busy_ = true;
    lock.unlock();
    for (Outgoing& m : sending_) {
      if (m.kind == Outgoing::Kind::Range) m.points = sending_points_.data() + m.first;
      if (m.kind == Outgoing::Kind::Image) m.bytes = sending_bytes_.data() + m.first;
      if (m.kind == Outgoing::Kind::RangeBearing) m.bytes = sending_bytes_.data() + m.first_byte;
      if (holdsValues(m.kind)) m.values = sending_values_.data() + m.first;
      if (m.kind == Outgoing::Kind::Odometry && m.robot == 0) {  // the round trip starts when it leaves
        std::lock_guard<std::mutex> guard(mutex_);
        sent_[nanos(m.odometry.time)] = std::chrono::steady_clock::now();
        while (sent_.size() > 1000) sent_.erase(sent_.begin());
      }
      send(m);
    }
    batchSent();
    sending_.clear();
    sending_points_.clear();
    sending_bytes_.clear();
    sending_values_.clear();
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

void Transport::receivedPose(std::size_t robot, double stamp, const std::array<double, 3>& position,
                             const std::array<double, 4>& orientation_wxyz) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queued_.at(robot) >= kMaxPosesQueued) {
      // (nobody took them: the simulation is not stepping; a client cannot make the queue grow)
      const auto oldest = std::find_if(poses_.begin(), poses_.end(), [&](const PoseSample& p) { return p.robot == robot; });
      poses_.erase(oldest);
      --queued_[robot];
      ++poses_dropped_;
    }
    poses_.push_back({robot, stamp, position, orientation_wxyz});
    ++queued_[robot];
    newest_pose_[robot] = std::max(newest_pose_[robot], stamp);
    ++received_;
    received_count_.store(received_, std::memory_order_release);
  }
  arrived_.notify_all();
}

void Transport::receivedJoy(std::size_t robot, double stamp, const float* axes, std::size_t axis_count,
                            const int* buttons, std::size_t button_count) {
  constexpr std::size_t kMax = 64;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Joy& j = joys_.at(robot);
    j.stamp = stamp;
    j.axes.assign(axes, axes + std::min(axis_count, kMax));
    j.buttons.assign(buttons, buttons + std::min(button_count, kMax));
    ++j.count;
    j.order = ++received_;
    received_count_.store(received_, std::memory_order_release);
  }
  arrived_.notify_all();
}

void Transport::receivedJointCommand(std::size_t robot, const char* const* names, std::size_t name_count,
                                     const double* positions, std::size_t position_count, const double* velocities,
                                     std::size_t velocity_count) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    JointCommand& j = joint_commands_.at(robot);
    j.names.clear();
    for (std::size_t k = 0; k < std::min(name_count, kMaxJoints); ++k)
      j.names.emplace_back(names[k] != nullptr ? std::string(names[k]).substr(0, 256) : std::string());
    j.positions.assign(positions, positions + std::min(position_count, kMaxJoints));
    j.velocities.assign(velocities, velocities + std::min(velocity_count, kMaxJoints));
    ++j.count;
    j.order = ++received_;
    received_count_.store(received_, std::memory_order_release);
  }
  arrived_.notify_all();
}

JointCommand Transport::latestJointCommand(std::size_t robot) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return joint_commands_.at(robot);
}

Joy Transport::latestJoy(std::size_t robot) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return joys_.at(robot);
}

void Transport::takePoses(std::vector<PoseSample>& out) {
  out.clear();
  std::lock_guard<std::mutex> lock(mutex_);
  out.swap(poses_);
  std::fill(queued_.begin(), queued_.end(), 0);
}

std::uint64_t Transport::posesDropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_dropped_;
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
    if ((robots_[i].setpoint && (setpoints_[i].count == 0 || setpoints_[i].stamp < time - 1e-9)) ||
        (robots_[i].ghost && newest_pose_[i] < time - 1e-9) || (robots_[i].joy && joys_[i].stamp < time - 1e-9))
      names.push_back(robots_[i].name);
  return names;
}

std::vector<std::string> Transport::waitForSetpoints(double time, double timeout_s,
                                                     const std::function<bool()>& stop) const {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(timeout_s));
  std::unique_lock<std::mutex> lock(mutex_);
  // (in slices, between which the stop flag, which nobody notifies, is looked at)
  while (!missingSetpoints(time).empty() && std::chrono::steady_clock::now() < deadline && !stop())
    arrived_.wait_until(lock, std::min(deadline, std::chrono::steady_clock::now() + std::chrono::milliseconds(20)),
                        [&] { return missingSetpoints(time).empty(); });
  return missingSetpoints(time);
}

std::vector<std::string> Transport::waitForPeers(double timeout_s, const std::function<bool()>& stop) const {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::vector<std::string> missing;
  for (;;) {
    missing.clear();
    for (std::size_t i = 0; i < robots_.size(); ++i)
      if ((robots_[i].setpoint || robots_[i].ghost || robots_[i].joy) && !connected(i)) missing.push_back(robots_[i].name);
    if (missing.empty() || std::chrono::steady_clock::now() >= deadline || stop()) return missing;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::vector<double> Transport::roundTrips() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return round_trips_;
}

}  // namespace ssx::bridge
