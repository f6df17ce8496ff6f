// pose: ground-truth pose and twist of a node (ssx::PoseMeasurement), with optional Gaussian noise
// drawn from the sensor's own stream (so runs repeat on any number of threads).
//
// Parameters:
//   node                    physic node to measure (default: the first root)
//   position_noise          standard deviation per axis, m (default 0)
//   orientation_noise       standard deviation of a small rotation per axis, rad (default 0)
//   velocity_noise          m/s (default 0)
//   angular_velocity_noise  rad/s (default 0)
#include <ssx/artifact.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

namespace ssx::plugins {

class PoseSensor final : public SensorOf<PoseMeasurement> {
 public:
  void configure(const Descriptor& params) override {
    node_ = &artifact().nodeFromParameter(params);
    position_noise_ = nonNegative(params, "position_noise");
    orientation_noise_ = nonNegative(params, "orientation_noise");
    velocity_noise_ = nonNegative(params, "velocity_noise");
    angular_velocity_noise_ = nonNegative(params, "angular_velocity_noise");
  }

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
  static double nonNegative(const Descriptor& params, const char* key) {
    const double v = params.get<double>(key, 0.0);
    if (v < 0) throw params.error(*params.find(key), std::string(key) + " must not be negative");
    return v;
  }
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
