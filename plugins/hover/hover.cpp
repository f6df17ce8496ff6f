// hover: holds a rigid body at a set-point with a PD law on position and attitude, applying a
// force and a torque at the centre of mass (no rotors: the quadrotor driver models those).
//
// It reads the artifact's first pose sensor (any sensor producing ssx::PoseMeasurement) when it
// has one, so sensor noise reaches the controller; otherwise the ground truth.
//
// Parameters:
//   target  "x y z", m (default: where the artifact starts, plus offset)
//   offset  "x y z", m, added to the start when no target is given (default 0 0 0)
//   yaw     rad (default 0)
//   kp, kd  position gains, 1/s^2 and 1/s (default 16, 8: critically damped at 4 rad/s)
//   kr, kw  attitude gains, 1/s^2 and 1/s (default 36, 12)
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

namespace ssx::plugins {

class HoverDriver final : public Driver {
 public:
  void configure(const Descriptor& params) override {
    Artifact& a = artifact();
    const Vec3 offset = params.get<Vec3>("offset", Vec3::Zero());
    target_ = params.get<Vec3>("target", Vec3(a.placement().position + offset));
    const double yaw = params.get<double>("yaw", 0.0);
    target_orientation_ = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
    kp_ = params.getPositive("kp", 16.0);
    kd_ = params.getPositive("kd", 8.0);
    kr_ = params.getPositive("kr", 36.0);
    kw_ = params.getPositive("kw", 12.0);
    if (a.rootCount() == 0 || a.root().isStatic()) throw params.error("hover needs a dynamic physic root");
    const MassProperties mass = combinedMass(a.root().spec());
    mass_ = mass.mass;
    inertia_ = mass.inertia;
    gravity_ = environment().settings().physics.gravity;
    // use the first pose sensor of this artifact, if any
    for (std::size_t i = 0; i < a.sensorCount(); ++i) {
      if (dynamic_cast<const PoseMeasurement*>(&a.sensor(i).latest()) == nullptr) continue;
      environment().subscribe<PoseMeasurement>(a.sensor(i), a, [this](const PoseMeasurement& m) {
        measured_ = m;
        have_measurement_ = true;
      });
      break;
    }
  }

  void step(const StepInfo&) override {
    PhysicNode& body = artifact().root();
    if (!have_measurement_) {
      const BodyState s = body.state();
      measured_.pose = s.pose;
      measured_.linear_velocity = s.linear_velocity;
      measured_.angular_velocity = s.angular_velocity;
    }
    const Pose& p = measured_.pose;
    // position: PD plus weight compensation
    const Vec3 force = mass_ * (kp_ * (target_ - p.position) - kd_ * measured_.linear_velocity - gravity_);
    // attitude: rotate towards the target orientation along the shortest way
    Quat error = target_orientation_ * p.orientation.conjugate();
    if (error.w() < 0) error.coeffs() = -error.coeffs();
    const Eigen::AngleAxisd aa(error);
    const Vec3 rotation = aa.angle() * aa.axis();
    const Mat3 r = p.orientation.toRotationMatrix();
    const Vec3 torque = r * inertia_ * r.transpose() * (kr_ * rotation - kw_ * measured_.angular_velocity);
    body.addForce(force);
    body.addTorque(torque);
  }

 private:
  Vec3 target_ = Vec3::Zero();
  Quat target_orientation_ = Quat::Identity();
  double kp_ = 0, kd_ = 0, kr_ = 0, kw_ = 0, mass_ = 0;
  Mat3 inertia_ = Mat3::Identity();
  Vec3 gravity_ = Vec3::Zero();
  PoseMeasurement measured_;
  bool have_measurement_ = false;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_DRIVER(ssx::plugins::HoverDriver, "hover"));
