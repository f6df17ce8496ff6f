// The ROS 1 side of the ros1 extension (C++17). See ros_bridge.hpp.
#include "ros_bridge.hpp"

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/WrenchStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/Joy.h>

#include <chrono>
#include <stdexcept>
#include <thread>

namespace ssx::ros1 {

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

class RosTransport final : public bridge::Transport {
 public:
  RosTransport(const std::string& master_uri, const std::string& node_name, double timeout_s,
               const std::vector<bridge::RobotTopics>& robots);
  ~RosTransport() override { shutdown(); }
  void shutdown();

 private:
  void send(const bridge::Outgoing& out) override;
  bool connected(std::size_t robot) const override {
    const bridge::RobotTopics& r = robots()[robot];
    return (!r.odom || odom_[robot].getNumSubscribers() > 0) &&
           (!r.setpoint || setpoint_subscribers_[robot].getNumPublishers() > 0) &&
           (!r.ghost || pose_subscribers_[robot].getNumPublishers() > 0) &&
           (!r.joy || joy_subscribers_[robot].getNumPublishers() > 0);
  }

  std::unique_ptr<ros::NodeHandle> node_;
  std::unique_ptr<ros::AsyncSpinner> spinner_;
  ros::Publisher clock_;
  std::vector<ros::Publisher> odom_, imu_, range_, force_, image_;
  std::vector<ros::Subscriber> setpoint_subscribers_, velocity_subscribers_, pose_subscribers_, joy_subscribers_;  // per robot (empty where none)
  bool running_ = false;
};

RosTransport::RosTransport(const std::string& master_uri, const std::string& node_name, double timeout_s,
                           const std::vector<bridge::RobotTopics>& robots)
    : Transport(robots) {
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
  running_ = true;
  node_ = std::make_unique<ros::NodeHandle>();
  clock_ = node_->advertise<rosgraph_msgs::Clock>("/clock", 10);
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const std::string ns = "/" + robots[i].name;
    odom_.push_back(robots[i].odom ? node_->advertise<nav_msgs::Odometry>(ns + "/odom", 10) : ros::Publisher());
    image_.push_back(robots[i].image ? node_->advertise<sensor_msgs::Image>(ns + "/image", 2) : ros::Publisher());
    force_.push_back(robots[i].force ? node_->advertise<geometry_msgs::WrenchStamped>(ns + "/force", 10) : ros::Publisher());
    imu_.push_back(robots[i].imu ? node_->advertise<sensor_msgs::Imu>(ns + "/imu", 10) : ros::Publisher());
    ros::Subscriber setpoints, velocities;
    if (robots[i].setpoint) {
      auto on_setpoint = [this, i](const geometry_msgs::PoseStamped::ConstPtr& m) {
        receivedSetpoint(i, m->header.stamp.toSec(), {m->pose.position.x, m->pose.position.y, m->pose.position.z},
                         {m->pose.orientation.w, m->pose.orientation.x, m->pose.orientation.y, m->pose.orientation.z});
      };
      setpoints = node_->subscribe<geometry_msgs::PoseStamped>(ns + "/setpoint", 10, on_setpoint, ros::VoidConstPtr(),
                                                                ros::TransportHints().tcpNoDelay());
    }
    if (robots[i].velocity) {
      auto on_velocity = [this, i](const geometry_msgs::Twist::ConstPtr& m) {
        receivedVelocity(i, {m->linear.x, m->linear.y, m->linear.z}, {m->angular.x, m->angular.y, m->angular.z});
      };
      velocities = node_->subscribe<geometry_msgs::Twist>(ns + "/cmd_vel", 10, on_velocity, ros::VoidConstPtr(),
                                                           ros::TransportHints().tcpNoDelay());
    }
    ros::Subscriber poses;
    if (robots[i].ghost) {
      // (a queue deep enough for a motion-capture burst: every pose counts)
      auto on_pose = [this, i](const geometry_msgs::PoseStamped::ConstPtr& m) {
        receivedPose(i, m->header.stamp.toSec(), {m->pose.position.x, m->pose.position.y, m->pose.position.z},
                     {m->pose.orientation.w, m->pose.orientation.x, m->pose.orientation.y, m->pose.orientation.z});
      };
      poses = node_->subscribe<geometry_msgs::PoseStamped>(ns + "/pose", 100, on_pose, ros::VoidConstPtr(),
                                                            ros::TransportHints().tcpNoDelay());
    }
    ros::Subscriber joys;
    if (robots[i].joy) {
      auto on_joy = [this, i](const sensor_msgs::Joy::ConstPtr& m) {
        receivedJoy(i, m->header.stamp.toSec(), m->axes.data(), m->axes.size(), m->buttons.data(), m->buttons.size());
      };
      joys = node_->subscribe<sensor_msgs::Joy>(ns + "/joy", 10, on_joy, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    }
    joy_subscribers_.push_back(joys);
    range_.push_back(robots[i].range ? node_->advertise<geometry_msgs::PoseArray>(ns + "/range", 10) : ros::Publisher());
    setpoint_subscribers_.push_back(setpoints);
    velocity_subscribers_.push_back(velocities);
    pose_subscribers_.push_back(poses);
  }
  spinner_ = std::make_unique<ros::AsyncSpinner>(1);
  spinner_->start();
  startPublishing();
}

void RosTransport::shutdown() {
  if (!running_) return;
  running_ = false;
  stopPublishing();  // after sending what was staged
  if (spinner_) spinner_->stop();
  setpoint_subscribers_.clear();
  velocity_subscribers_.clear();
  pose_subscribers_.clear();
  joy_subscribers_.clear();
  force_.clear();
  image_.clear();
  odom_.clear();
  range_.clear();
  imu_.clear();
  clock_ = ros::Publisher();
  spinner_.reset();
  node_.reset();
  ros::shutdown();
}

void RosTransport::send(const bridge::Outgoing& out) {
  switch (out.kind) {
    case bridge::Outgoing::Kind::Clock: {
      rosgraph_msgs::Clock m;
      m.clock = stamp(out.time);
      clock_.publish(m);
      break;
    }
    case bridge::Outgoing::Kind::Odometry: {
      const bridge::Odometry& o = out.odometry;
      nav_msgs::Odometry m;
      m.header.stamp = stamp(o.time);
      m.header.frame_id = "world";
      m.child_frame_id = robots()[out.robot].name + "/base_link";
      setXyz(m.pose.pose.position, o.position);
      setWxyz(m.pose.pose.orientation, o.orientation);
      setXyz(m.twist.twist.linear, o.velocity);
      setXyz(m.twist.twist.angular, o.angular_velocity);
      odom_[out.robot].publish(m);
      break;
    }
    case bridge::Outgoing::Kind::Imu: {
      const bridge::Imu& u = out.imu;
      sensor_msgs::Imu m;
      m.header.stamp = stamp(u.time);
      m.header.frame_id = robots()[out.robot].name + "/imu";
      setWxyz(m.orientation, u.orientation);
      setXyz(m.angular_velocity, u.angular_velocity);
      setXyz(m.linear_acceleration, u.linear_acceleration);
      imu_[out.robot].publish(m);
      break;
    }
    case bridge::Outgoing::Kind::Image: {
      sensor_msgs::Image m;
      m.header.stamp = stamp(out.time);
      m.header.frame_id = robots()[out.robot].name + "/camera";
      m.height = static_cast<std::uint32_t>(out.height);
      m.width = static_cast<std::uint32_t>(out.width);
      m.encoding = "rgb8";
      m.step = static_cast<std::uint32_t>(3 * out.width);
      m.data.assign(out.bytes, out.bytes + out.count);
      image_[out.robot].publish(m);
      break;
    }
    case bridge::Outgoing::Kind::Force: {
      geometry_msgs::WrenchStamped m;
      m.header.stamp = stamp(out.time);
      m.header.frame_id = "world";
      setXyz(m.wrench.force, out.force);
      force_[out.robot].publish(m);
      break;
    }
    case bridge::Outgoing::Kind::Range: {
      // each detection a pose at its relative position (orientation the identity), nearest first
      geometry_msgs::PoseArray m;
      m.header.stamp = stamp(out.time);
      m.header.frame_id = out.body_frame ? robots()[out.robot].name + "/base_link" : "world";
      m.poses.resize(out.count);
      for (std::size_t k = 0; k < out.count; ++k) {
        setXyz(m.poses[k].position, out.points[k]);
        m.poses[k].orientation.w = 1;
      }
      range_[out.robot].publish(m);
      break;
    }
    case bridge::Outgoing::Kind::Transforms:
    case bridge::Outgoing::Kind::JointStates:
    case bridge::Outgoing::Kind::Scan:
    case bridge::Outgoing::Kind::Ground:
    case bridge::Outgoing::Kind::RangeBearing:
      break;  // (the ROS 2 bridge's: this one's robots never ask for /tf, RobotTopics::tf)
  }
}

}  // namespace

std::unique_ptr<bridge::Transport> open(const std::string& master_uri, const std::string& node_name, double timeout_s,
                                        const std::vector<bridge::RobotTopics>& robots) {
  return std::make_unique<RosTransport>(master_uri, node_name, timeout_s, robots);
}

void close(bridge::Transport& transport) { static_cast<RosTransport&>(transport).shutdown(); }

}  // namespace ssx::ros1
