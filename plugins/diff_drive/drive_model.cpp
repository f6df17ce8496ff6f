#include "drive_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace ssx::ground {

double yawOf(const Quat& q) {
  return std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()));
}

double wrapAngle(double a) {
  constexpr double kPi = std::numbers::pi;
  a = std::remainder(a, 2 * kPi);
  return a <= -kPi ? a + 2 * kPi : a;
}

namespace {

// a side's wheel nodes: names separated by spaces
std::vector<std::string> wheelNames(const Descriptor& params, const char* key) {
  std::vector<std::string> names;
  std::istringstream in(params.get<std::string>(key, ""));
  for (std::string name; in >> name;) names.push_back(name);
  return names;
}

// the mean of a side's wheel speeds (one wheel's to the bit)
double meanSpeed(const std::vector<PhysicNode*>& wheels) {
  double sum = wheels.front()->jointVelocity();
  for (std::size_t i = 1; i < wheels.size(); ++i) sum += wheels[i]->jointVelocity();
  return wheels.size() == 1 ? sum : sum / static_cast<double>(wheels.size());
}

}  // namespace

void DriveModel::validate(const Descriptor& params, const Artifact& a) {
  if (a.rootCount() == 0 || a.root().isStatic()) throw params.error("diff_drive needs a dynamic physic root");
  if (params.get<std::string>("model") != "full") return;
  for (const char* key : {"left_wheel", "right_wheel"}) {
    const std::vector<std::string> names = wheelNames(params, key);
    if (names.empty())
      throw params.error(std::string("the full model needs '") + key + "' (the wheel's node, or the side's nodes)");
    for (const std::string& name : names) {
      const PhysicNode* n = a.node(name);
      if (n == nullptr) throw params.errorAt(key, "no physic node '" + name + "' in this artifact");
      if (n->joint().kind != JointSpec::Kind::Hinge || !(n->joint().max_effort > 0))
        throw params.errorAt(key, "node '" + name +
                                      "' must be joined by a hinge with a motor (max_torque; for a robot description "
                                      "without one, <joint node=\"" + name + "\" max_torque=\"...\"/> in its <type>)");
    }
  }
}

void DriveModel::configure(const Descriptor& params, Artifact& a) {
  artifact_ = &a;
  full_ = params.get<std::string>("model") == "full";
  radius_ = params.get<double>("wheel_radius");
  axle_ = params.get<double>("axle_length");
  max_wheel_ = params.get<double>("max_wheel_speed");
  noise_ = params.get<double>("encoder_noise");
  const PhysicsSettings& physics = a.environment().settings().physics;
  gravity_ = physics.gravity;
  const MassProperties m = bodyMass(a.root().spec());
  mass_ = m.mass;
  inertia_ = m.inertia;
  max_force_ = params.get<double>("max_force");
  if (max_force_ == 0) max_force_ = physics.friction * mass_ * gravity_.norm();
  max_torque_ = params.get<double>("max_torque");
  if (max_torque_ == 0) max_torque_ = max_force_ * axle_ / 2;
  if (full_) {
    for (const std::string& name : wheelNames(params, "left_wheel")) left_.push_back(a.node(name));
    for (const std::string& name : wheelNames(params, "right_wheel")) right_.push_back(a.node(name));
  }
  height_ = a.root().state().pose.position.z();
}

void DriveModel::setWheels(double left, double right) {
  const double fastest = std::max(std::abs(left), std::abs(right));
  const double scale = fastest > max_wheel_ ? max_wheel_ / fastest : 1.0;
  left_cmd_ = left * scale;
  right_cmd_ = right * scale;
}

void DriveModel::apply(double dt) {
  if (full_) {
    for (PhysicNode* wheel : left_) wheel->setJointVelocity(left_cmd_);
    for (PhysicNode* wheel : right_) wheel->setJointVelocity(right_cmd_);
  } else {
    drive(dt);
  }
}

// the swarm model: the body driven to the wheels' twist, and held on its plane, each within one step
void DriveModel::drive(double dt) {
  PhysicNode& root = artifact_->root();
  const BodyState body = artifact_->environment().bodyState(root.bodyIndex());  // at the centre of mass
  const Quat& q = body.pose.orientation;
  const double yaw = yawOf(q);
  const Vec3 forward(std::cos(yaw), std::sin(yaw), 0);
  const double v = radius_ * (left_cmd_ + right_cmd_) / 2;
  const double w = radius_ * (right_cmd_ - left_cmd_) / axle_;
  // in the plane: the velocity the wheels give (no sideways slip), with at most max_force
  Vec3 change = v * forward - Vec3(body.linear_velocity.x(), body.linear_velocity.y(), 0);
  Vec3 force = mass_ * change / dt;
  if (force.norm() > max_force_) force *= max_force_ / force.norm();
  // its height and upright: held (the weight carried), as the floor and its wheels would
  const double root_z = root.pose().position.z();
  force.z() = mass_ * ((height_ - root_z) / dt - body.linear_velocity.z()) / dt - mass_ * gravity_.z();
  Quat upright(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
  Quat tilt = upright * q.conjugate();
  if (tilt.w() < 0) tilt.coeffs() = -tilt.coeffs();
  const Eigen::AngleAxisd aa(tilt);
  Vec3 target = aa.angle() * aa.axis() / dt;
  target.z() = w;
  const Mat3 r = q.toRotationMatrix();
  const Mat3 inertia = r * inertia_ * r.transpose();
  Vec3 torque = inertia * (target - body.angular_velocity) / dt;
  torque.z() = std::clamp(torque.z(), -max_torque_, max_torque_);
  root.addForce(force, Frame::World, body.pose.position, Frame::World);
  root.addTorque(torque);
}

// the encoders, and the pose dead-reckoned from them (midpoint heading)
void DriveModel::measure(double dt, Random& random) {
  double left = 0, right = 0;
  if (full_) {
    left = meanSpeed(left_);
    right = meanSpeed(right_);
  } else {
    const BodyState s = artifact_->root().state();
    const double yaw = yawOf(s.pose.orientation);
    const double v = s.linear_velocity.x() * std::cos(yaw) + s.linear_velocity.y() * std::sin(yaw);
    left = (v - s.angular_velocity.z() * axle_ / 2) / radius_;
    right = (v + s.angular_velocity.z() * axle_ / 2) / radius_;
  }
  if (noise_ > 0) {
    left += random.normal(0.0, noise_);
    right += random.normal(0.0, noise_);
  }
  Odometry& o = odometry_;
  o.left_speed = left;
  o.right_speed = right;
  o.left_angle += left * dt;
  o.right_angle += right * dt;
  o.forward = radius_ * (left + right) / 2;
  o.yaw_rate = radius_ * (right - left) / axle_;
  const double mid = o.yaw + o.yaw_rate * dt / 2;
  o.x += o.forward * std::cos(mid) * dt;
  o.y += o.forward * std::sin(mid) * dt;
  o.yaw = wrapAngle(o.yaw + o.yaw_rate * dt);
}

void DriveModel::saveState(StateWriter& out) const {
  out.write(left_cmd_);
  out.write(right_cmd_);
  out.bytes(&odometry_, sizeof odometry_);
}

void DriveModel::loadState(StateReader& in) {
  in.read(left_cmd_);
  in.read(right_cmd_);
  in.bytes(&odometry_, sizeof odometry_);
}

}  // namespace ssx::ground
