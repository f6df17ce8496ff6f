// hover: holds a rigid body at a set-point with a PD law on position and attitude, applying a
// force and a torque at the centre of mass (no rotors: the quadrotor driver models those).
//
// It reads the artifact's first pose sensor (any sensor producing ssx::PoseMeasurement) when it
// has one, so sensor noise reaches the controller; otherwise the ground truth.
//
// Parameters: kParameters below, or `ssx plugins --params hover`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

namespace ssx::plugins {

class HoverDriver final : public Driver {
 public:
  static constexpr const char* kDoc = "holds a rigid body at a set-point with a PD law (force and torque, no rotors)";
  static constexpr ssx_plugin_param kParameters[] = {
      param::vec3("target", "", "m", param::any(), "set-point (default: where the artifact starts, plus offset)"),
      param::vec3("offset", "0 0 0", "m", param::any(), "added to the start when no target is given"),
      param::real("yaw", "0", "rad", param::any(), "heading to hold"),
      param::real("kp", "16", "1/s^2", param::positive(), "position gain"),
      param::real("kd", "8", "1/s", param::positive(), "velocity gain (16, 8: critically damped at 4 rad/s)"),
      param::real("kr", "36", "1/s^2", param::positive(), "attitude gain"),
      param::real("kw", "12", "1/s", param::positive(), "angular velocity gain"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    const Artifact& a = *context.artifact;
    if (a.rootCount() == 0 || a.root().isStatic()) throw params.error("hover needs a dynamic physic root");
  }

  void configure(const Descriptor& params, PluginSetup& setup) override {
    Artifact& a = artifact();
    const Vec3 offset = params.get<Vec3>("offset");
    target_ = params.get<Vec3>("target", Vec3(a.placement().position + offset));
    target_orientation_ = Quat(Eigen::AngleAxisd(params.get<double>("yaw"), Vec3::UnitZ()));
    kp_ = params.get<double>("kp");
    kd_ = params.get<double>("kd");
    kr_ = params.get<double>("kr");
    kw_ = params.get<double>("kw");
    const MassProperties mass = combinedMass(a.root().spec());
    mass_ = mass.mass;
    inertia_ = mass.inertia;
    gravity_ = environment().settings().physics.gravity;
    // use the first pose sensor of this artifact, if any
    for (std::size_t i = 0; i < a.sensorCount(); ++i) {
      if (dynamic_cast<const PoseMeasurement*>(&a.sensor(i).latest()) == nullptr) continue;
      setup.subscribe<PoseMeasurement>(a.sensor(i), [this](const PoseMeasurement& m) {
        measured_ = m;
        have_measurement_ = true;
      });
      break;
    }
  }

  void saveState(StateWriter& out) const override {
    save(out, measured_);
    out.write(have_measurement_);
  }
  void loadState(StateReader& in) override {
    load(in, measured_);
    in.read(have_measurement_);
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
