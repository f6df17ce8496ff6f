// The ROS 1 side of the ros1 extension (C++17). See ros_bridge.hpp.
#include "ros_bridge.hpp"

#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/Imu.h>

#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace ssx::ros1 {

struct Bridge::Impl {
  std::unique_ptr<ros::NodeHandle> node;
  std::unique_ptr<ros::AsyncSpinner> spinner;
  ros::Publisher clock;
  std::vector<RobotTopics> robots;
  std::vector<ros::Publisher> odom, imu;
  std::vector<ros::Subscriber> setpoint_subscribers;
  mutable std::mutex mutex;
  mutable std::condition_variable arrived;
  std::vector<Setpoint> setpoints;  // guarded by mutex
  std::map<double, std::chrono::steady_clock::time_point> published;  // odometry time -> wall time; mutex
  std::vector<double> round_trips;                                     // mutex
  bool running = false;

  // the publishing thread: the stepping thread queues plain messages, this one serialises them
  struct Outgoing {
    enum class Kind : std::uint8_t { Clock, Odometry, Imu } kind;
    std::size_t robot;
    double time;  // clock
    Odometry odometry;
    Imu imu;
  };
  std::mutex queue_mutex;
  std::condition_variable queue_changed;
  std::vector<Outgoing> staged;          // the stepping thread's, until commit hands them over
  std::vector<Outgoing> queue, sending;  // queue_mutex guards queue, busy, stop
  bool busy = false, stop = false;
  std::thread publisher;
  void enqueue(const Outgoing& m);
  void publishLoop();
  void send(const Outgoing& m);
};

namespace {
ros::Time stamp(double t) { return ros::Time(t < 0 ? 0.0 : t); }
// into any message with x, y, z (Point, Vector3) or w, x, y, z (Quaternion) fields
template <class V>
void setXyz(V& v, const std::array<double, 3>& a) {
  v.x = a[0];
  v.y = a[1];
  v.z = a[2];
}
template <class Q>
void setWxyz(Q& q, const std::array<double, 4>& a) {
  q.w = a[0];
  q.x = a[1];
  q.y = a[2];
  q.z = a[3];
}
}  // namespace

Bridge::Bridge(const std::string& master_uri, const std::string& node_name, double timeout_s,
               const std::vector<RobotTopics>& robots)
    : impl_(std::make_unique<Impl>()) {
  if (ros::isStarted()) throw std::runtime_error("a ROS node is already running in this process");
  // the host program keeps its own SIGINT handling (ssx stops cleanly on Ctrl-C)
  ros::M_string remappings{{"__master", master_uri}};
  ros::init(remappings, node_name, ros::init_options::NoSigintHandler | ros::init_options::NoRosout);
  // roscpp would wait for a master forever: ask it ourselves, with a deadline
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!ros::master::check()) {
    if (std::chrono::steady_clock::now() >= deadline)
      throw std::runtime_error("no ROS master answers at " + master_uri + " (waited " + std::to_string(timeout_s) +
                               " s): start one (roscore or rosmaster --core -p PORT) or set master_uri / "
                               "ROS_MASTER_URI");
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ros::start();
  Impl& d = *impl_;
  d.running = true;
  d.node = std::make_unique<ros::NodeHandle>();
  d.clock = d.node->advertise<rosgraph_msgs::Clock>("/clock", 10);
  d.robots = robots;
  d.setpoints.assign(robots.size(), Setpoint{});
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const std::string ns = "/" + robots[i].name;
    d.odom.push_back(d.node->advertise<nav_msgs::Odometry>(ns + "/odom", 10));
    d.imu.push_back(robots[i].imu ? d.node->advertise<sensor_msgs::Imu>(ns + "/imu", 10) : ros::Publisher());
    if (robots[i].setpoint) {
      Impl* self = impl_.get();
      auto on_setpoint = [self, i](const geometry_msgs::PoseStamped::ConstPtr& m) {
        {
          std::lock_guard<std::mutex> lock(self->mutex);
          Setpoint& s = self->setpoints[i];
          s.stamp = m->header.stamp.toSec();
          const auto sent = self->published.find(s.stamp);
          if (sent != self->published.end())
            self->round_trips.push_back(
                std::chrono::duration<double>(std::chrono::steady_clock::now() - sent->second).count());
          s.position = {m->pose.position.x, m->pose.position.y, m->pose.position.z};
          s.orientation = {m->pose.orientation.w, m->pose.orientation.x, m->pose.orientation.y, m->pose.orientation.z};
          ++s.count;
        }
        self->arrived.notify_all();
      };
      d.setpoint_subscribers.push_back(d.node->subscribe<geometry_msgs::PoseStamped>(
          ns + "/setpoint", 10, on_setpoint, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
    }
  }
  d.spinner = std::make_unique<ros::AsyncSpinner>(1);
  d.spinner->start();
  d.queue.reserve(4 * robots.size() + 16);
  d.sending.reserve(4 * robots.size() + 16);
  d.staged.reserve(4 * robots.size() + 16);
  d.publisher = std::thread([&d] { d.publishLoop(); });
}

void Bridge::Impl::enqueue(const Outgoing& m) { staged.push_back(m); }

void Bridge::commit() {
  Impl& d = *impl_;
  if (d.staged.empty()) return;  // (most steps publish nothing: no lock, no wake-up)
  {
    // one lock per step, however many robots: the buffers trade places, so none is allocated
    std::lock_guard<std::mutex> lock(d.queue_mutex);
    if (d.queue.empty())
      d.queue.swap(d.staged);
    else
      d.queue.insert(d.queue.end(), d.staged.begin(), d.staged.end());
  }
  d.staged.clear();
  d.queue_changed.notify_all();
}

void Bridge::Impl::publishLoop() {
  std::unique_lock<std::mutex> lock(queue_mutex);
  for (;;) {
    queue_changed.wait(lock, [&] { return stop || !queue.empty(); });
    if (queue.empty() && stop) return;
    sending.swap(queue);
    busy = true;
    lock.unlock();
    for (const Outgoing& m : sending) send(m);
    sending.clear();
    lock.lock();
    busy = false;
    queue_changed.notify_all();  // (flush waits for this)
  }
}

void Bridge::flush() {
  Impl& d = *impl_;
  commit();
  d.queue_changed.notify_all();
  std::unique_lock<std::mutex> lock(d.queue_mutex);
  d.queue_changed.wait(lock, [&] { return d.queue.empty() && !d.busy; });
}

Bridge::~Bridge() { shutdown(); }

void Bridge::shutdown() {
  Impl& d = *impl_;
  if (!d.running) return;
  d.running = false;
  if (d.publisher.joinable()) {
    commit();
    {
      std::lock_guard<std::mutex> lock(d.queue_mutex);
      d.stop = true;
    }
    d.queue_changed.notify_all();
    d.publisher.join();  // after sending what was queued
  }
  if (d.spinner) d.spinner->stop();
  d.setpoint_subscribers.clear();
  d.odom.clear();
  d.imu.clear();
  d.clock = ros::Publisher();
  d.spinner.reset();
  d.node.reset();
  ros::shutdown();
}

void Bridge::publishClock(double time) {
  Impl::Outgoing m{};
  m.kind = Impl::Outgoing::Kind::Clock;
  m.time = time;
  impl_->enqueue(m);
}

void Bridge::publishOdometry(std::size_t robot, const Odometry& o) {
  Impl::Outgoing m{};
  m.kind = Impl::Outgoing::Kind::Odometry;
  m.robot = robot;
  m.odometry = o;
  impl_->enqueue(m);
}

void Bridge::publishImu(std::size_t robot, const Imu& u) {
  if (!impl_->robots[robot].imu) return;
  Impl::Outgoing m{};
  m.kind = Impl::Outgoing::Kind::Imu;
  m.robot = robot;
  m.imu = u;
  impl_->enqueue(m);
}

void Bridge::Impl::send(const Outgoing& out) {
  switch (out.kind) {
    case Outgoing::Kind::Clock: {
      rosgraph_msgs::Clock m;
      m.clock = stamp(out.time);
      clock.publish(m);
      break;
    }
    case Outgoing::Kind::Odometry: {
      const Odometry& o = out.odometry;
      if (out.robot == 0) {  // the round trip starts when it leaves
        std::lock_guard<std::mutex> lock(mutex);
        published[stamp(o.time).toSec()] = std::chrono::steady_clock::now();
        while (published.size() > 1000) published.erase(published.begin());
      }
      nav_msgs::Odometry m;
      m.header.stamp = stamp(o.time);
      m.header.frame_id = "world";
      m.child_frame_id = robots[out.robot].name + "/base_link";
      setXyz(m.pose.pose.position, o.position);
      setWxyz(m.pose.pose.orientation, o.orientation);
      setXyz(m.twist.twist.linear, o.velocity);
      setXyz(m.twist.twist.angular, o.angular_velocity);
      odom[out.robot].publish(m);
      break;
    }
    case Outgoing::Kind::Imu: {
      const Imu& u = out.imu;
      sensor_msgs::Imu m;
      m.header.stamp = stamp(u.time);
      m.header.frame_id = robots[out.robot].name + "/imu";
      setWxyz(m.orientation, u.orientation);
      setXyz(m.angular_velocity, u.angular_velocity);
      setXyz(m.linear_acceleration, u.linear_acceleration);
      imu[out.robot].publish(m);
      break;
    }
  }
}

std::vector<std::string> Bridge::waitForPeers(double timeout_s) const {
  const Impl& d = *impl_;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::vector<std::string> missing;
  for (;;) {
    missing.clear();
    std::size_t k = 0;  // index into the set-point subscribers
    for (std::size_t i = 0; i < d.robots.size(); ++i) {
      if (!d.robots[i].setpoint) continue;
      if (d.odom[i].getNumSubscribers() == 0 || d.setpoint_subscribers[k].getNumPublishers() == 0)
        missing.push_back(d.robots[i].name);
      ++k;
    }
    if (missing.empty() || std::chrono::steady_clock::now() >= deadline) return missing;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::vector<double> Bridge::roundTrips() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->round_trips;
}

Setpoint Bridge::latestSetpoint(std::size_t robot) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->setpoints.at(robot);
}

std::vector<std::string> Bridge::waitForSetpoints(double time, double timeout_s) const {
  Impl& d = *impl_;
  auto missing = [&] {
    std::vector<std::string> names;
    for (std::size_t i = 0; i < d.robots.size(); ++i)
      if (d.robots[i].setpoint && (d.setpoints[i].count == 0 || d.setpoints[i].stamp < time - 1e-9))
        names.push_back(d.robots[i].name);
    return names;
  };
  std::unique_lock<std::mutex> lock(d.mutex);
  d.arrived.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return missing().empty(); });
  return missing();
}

}  // namespace ssx::ros1
