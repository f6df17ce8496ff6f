// imu: accelerometer and gyroscope (ssx::ImuMeasurement) with the error model of
// shared/specs/quadrotor.md section 3, per axis:
//   measured = scale * (true + turn-on bias + Gauss-Markov bias + white noise),
//   then quantised to counts of one LSB and saturated at the range.
// The accelerometer measures specific force R^T (a - g) at the IMU node (lever-arm terms included
// through the node's rigid-body kinematics). Noise comes from the sensor's own stream, seeded from
// (scene seed, artifact, plugin index).
//
// Parameters (defaults: ADIS16448, as RotorS):
//   node                         physic node the IMU sits on (default: the first root)
//   noise                        false turns every stochastic term off (default true)
//   gyro_noise_density           rad/s/sqrt(Hz) (3.394e-4)
//   gyro_bias_random_walk        rad/s^2/sqrt(Hz) (3.8785e-5)
//   gyro_bias_correlation_time   s (1000)
//   gyro_turn_on_bias            rad/s, standard deviation (8.7e-3)
//   gyro_scale                   scale factor (1)
//   gyro_lsb, gyro_range         rad/s per count (6.98e-4 = 0.04 deg/s), full scale (17.45 = 1000 deg/s)
//   accel_noise_density          m/s^2/sqrt(Hz) (4.0e-3)
//   accel_bias_random_walk       m/s^3/sqrt(Hz) (6.0e-3)
//   accel_bias_correlation_time  s (300)
//   accel_turn_on_bias           m/s^2 (0.196)
//   accel_scale                  (1)
//   accel_lsb, accel_range       m/s^2 per count (8.17e-3 = 0.833 mg), full scale (176.5 = 18 g)
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <cmath>

namespace ssx::plugins {

namespace {

// the error model of one three-axis instrument
struct Channel {
  double noise_density = 0, bias_random_walk = 0, correlation_time = 1, turn_on = 0, scale = 1, lsb = 1, range = 1;
  // discrete-time terms for the sensor's period
  double white_sigma = 0, bias_phi = 1, bias_sigma = 0;
  Vec3 turn_on_bias = Vec3::Zero();
  Vec3 bias = Vec3::Zero();

  void read(const Descriptor& p, const std::string& prefix, const Channel& defaults) {
    *this = defaults;
    auto positive = [&](const char* key, double fallback) { return p.getPositive(prefix + key, fallback); };
    auto nonNegative = [&](const char* key, double fallback) {
      const double v = p.get<double>(prefix + key, fallback);
      if (v < 0) throw p.error(*p.find(prefix + key), prefix + key + " must not be negative");
      return v;
    };
    noise_density = nonNegative("noise_density", noise_density);
    bias_random_walk = nonNegative("bias_random_walk", bias_random_walk);
    correlation_time = positive("bias_correlation_time", correlation_time);
    turn_on = nonNegative("turn_on_bias", turn_on);
    scale = positive("scale", scale);
    lsb = positive("lsb", lsb);
    range = positive("range", range);
  }

  void prepare(double dt, bool noise, Random& rng) {
    white_sigma = noise ? noise_density / std::sqrt(dt) : 0.0;
    bias_phi = std::exp(-dt / correlation_time);
    bias_sigma = noise ? std::sqrt(bias_random_walk * bias_random_walk * correlation_time / 2.0 *
                                   (1.0 - std::exp(-2.0 * dt / correlation_time)))
                       : 0.0;
    // draws in a fixed order (the order of function arguments is unspecified in C++)
    turn_on_bias.setZero();
    if (noise)
      for (int i = 0; i < 3; ++i) turn_on_bias[i] = rng.normal() * turn_on;
    bias.setZero();
  }

  // one reading: returns the value and writes the counts
  Vec3 measure(const Vec3& truth, Random& rng, std::array<std::int32_t, 3>& counts) {
    const auto max_count = static_cast<std::int64_t>(std::floor(range / lsb));
    Vec3 out;
    for (int i = 0; i < 3; ++i) {
      double white = 0;
      if (bias_sigma > 0) bias[i] = bias_phi * bias[i] + bias_sigma * rng.normal();
      if (white_sigma > 0) white = white_sigma * rng.normal();
      const double m = scale * (truth[i] + turn_on_bias[i] + bias[i] + white);
      std::int64_t c = std::llround(m / lsb);
      c = std::clamp<std::int64_t>(c, -max_count, max_count);
      counts[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(c);
      out[i] = static_cast<double>(c) * lsb;
    }
    return out;
  }
};

Channel gyroDefaults() {
  Channel c;
  c.noise_density = 3.394e-4;
  c.bias_random_walk = 3.8785e-5;
  c.correlation_time = 1000.0;
  c.turn_on = 8.7e-3;
  c.lsb = 0.04 * M_PI / 180.0;
  c.range = 1000.0 * M_PI / 180.0;
  return c;
}

Channel accelDefaults() {
  Channel c;
  c.noise_density = 4.0e-3;
  c.bias_random_walk = 6.0e-3;
  c.correlation_time = 300.0;
  c.turn_on = 0.196;
  c.lsb = 0.833e-3 * 9.80665;
  c.range = 18.0 * 9.80665;
  return c;
}

}  // namespace

class ImuSensor final : public SensorOf<ImuMeasurement> {
 public:
  void configure(const Descriptor& params) override {
    node_ = &artifact().nodeFromParameter(params);
    if (node_->isStatic()) throw params.error("an IMU needs a dynamic node");
    const bool noise = params.get<bool>("noise", true);
    gyro_.read(params, "gyro_", gyroDefaults());
    accel_.read(params, "accel_", accelDefaults());
    const double dt = toSeconds(periodSteps() * environment().timestep());
    gyro_.prepare(dt, noise, random());
    accel_.prepare(dt, noise, random());
    gravity_ = environment().settings().physics.gravity;
    output().accelerometer_lsb = accel_.lsb;
    output().gyroscope_lsb = gyro_.lsb;
  }

  void sense(const StepInfo& info) override {
    const BodyState s = node_->state();
    const Quat to_imu = s.pose.orientation.conjugate();
    ImuMeasurement& m = output();
    m.stamp = info.time;
    m.gyroscope = gyro_.measure(to_imu * s.angular_velocity, random(), m.gyroscope_counts);
    m.accelerometer = accel_.measure(to_imu * (s.linear_acceleration - gravity_), random(), m.accelerometer_counts);
  }

 private:
  const PhysicNode* node_ = nullptr;
  Channel gyro_, accel_;
  Vec3 gravity_ = Vec3::Zero();
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::ImuSensor, "imu"));
