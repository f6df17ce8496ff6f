// pose: ground-truth pose and twist of a node (ssx::PoseMeasurement), with optional Gaussian noise
// drawn from the sensor's own stream (so runs repeat on any number of threads).
//
// Parameters: kParameters below, or `ssx plugins --params pose`.
#include <ssx/artifact.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

namespace ssx::plugins {

class PoseSensor final : public SensorOf<PoseMeasurement> {
 public:
  static constexpr const char* kDoc = "pose and twist of a node (a motion-capture stand-in), optionally noisy";
  static constexpr ssx_plugin_param kParameters[] = {
      param::text("node", "", "physic node to measure (default: the first root)"),
      param::real("position_noise", "0", "m", param::nonNegative(), "standard deviation per axis"),
      param::real("orientation_noise", "0", "rad", param::nonNegative(),
                  "standard deviation of a small rotation per axis"),
      param::real("velocity_noise", "0", "m/s", param::nonNegative(), "standard deviation per axis"),
      param::real("angular_velocity_noise", "0", "rad/s", param::nonNegative(), "standard deviation per axis"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    (void)context.artifact->nodeFromParameter(params);
  }

  void configure(const Descriptor& params, PluginSetup& /*setup*/) override {
    node_ = &artifact().nodeFromParameter(params);
    position_noise_ = params.get<double>("position_noise");
    orientation_noise_ = params.get<double>("orientation_noise");
    velocity_noise_ = params.get<double>("velocity_noise");
    angular_velocity_noise_ = params.get<double>("angular_velocity_noise");
  }

  void saveState(StateWriter& out) const override { save(out, value()); }
  void loadState(StateReader& in) override { load(in, output()); }

  void sense(const StepInfo& info) override {
    const BodyState s = node_->state();
    PoseMeasurement& m = output();
    m.stamp = info.time;
    m.pose = s.pose;
    m.linear_velocity = s.linear_velocity;
    m.angular_velocity = s.angular_velocity;
    if (position_noise_ > 0) m.pose.position += noise(position_noise_);
    if (orientation_noise_ > 0) {
      const Vec3 r = noise(orientation_noise_);
      m.pose.orientation = (Quat(Eigen::AngleAxisd(r.norm(), r.normalized())) * m.pose.orientation).normalized();
    }
    if (velocity_noise_ > 0) m.linear_velocity += noise(velocity_noise_);
    if (angular_velocity_noise_ > 0) m.angular_velocity += noise(angular_velocity_noise_);
  }

 private:
  // three draws in a fixed order (the order of function arguments is unspecified in C++)
  Vec3 noise(double sigma) {
    Vec3 n;
    for (int i = 0; i < 3; ++i) n[i] = random().normal() * sigma;
    return n;
  }

  const PhysicNode* node_ = nullptr;
  double position_noise_ = 0, orientation_noise_ = 0, velocity_noise_ = 0, angular_velocity_noise_ = 0;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::PoseSensor, "pose"));
