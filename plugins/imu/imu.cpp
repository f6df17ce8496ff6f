// imu: accelerometer and gyroscope (ssx::ImuMeasurement) with the error model of
// docs/quadrotor-reference.md section 3, per axis:
//   measured = scale * (true + turn-on bias + Gauss-Markov bias + white noise),
//   then quantised to counts of one LSB and saturated at the range.
// The accelerometer measures specific force R^T (a - g) at the IMU node (lever-arm terms included
// through the node's rigid-body kinematics). Noise comes from the sensor's own stream, seeded from
// (scene seed, artifact, plugin index).
//
// Parameters: see kParameters below (defaults: ADIS16448, as RotorS), or `ssx plugins --params imu`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include "counts.hpp"

#include <cmath>
#include <cstdio>

namespace ssx::plugins {

// the most counts a reading may have, each way (24-bit converters)
constexpr double kMaxCounts = 16777216.0;

namespace {

// the error model of one three-axis instrument
struct Channel {
  double noise_density = 0, bias_random_walk = 0, correlation_time = 1, turn_on = 0, scale = 1, lsb = 1, range = 1;
  // discrete-time terms for the sensor's period
  double white_sigma = 0, bias_phi = 1, bias_sigma = 0;
  double white_configured = 0, bias_configured = 0;  // as configured: noiseFactor scales them
  double max_count = 1;  // counts at full scale, each way: floor(range / lsb)
  Vec3 turn_on_bias = Vec3::Zero();
  Vec3 bias = Vec3::Zero();

  // the values were checked against the declarations while loading
  void read(const Descriptor& p, const std::string& prefix) {
    noise_density = p.get<double>(prefix + "noise_density");
    bias_random_walk = p.get<double>(prefix + "bias_random_walk");
    correlation_time = p.get<double>(prefix + "bias_correlation_time");
    turn_on = p.get<double>(prefix + "turn_on_bias");
    scale = p.get<double>(prefix + "scale");
    lsb = p.get<double>(prefix + "lsb");
    range = p.get<double>(prefix + "range");
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
    white_configured = white_sigma;
    bias_configured = bias_sigma;
    bias.setZero();
    max_count = static_cast<double>(static_cast<std::int64_t>(std::floor(range / lsb)));
  }

  // white noise and bias walk at `factor` times the configured ones (a learning episode's draw)
  void noiseFactor(double factor) {
    white_sigma = factor * white_configured;
    bias_sigma = factor * bias_configured;
  }

  // one reading: returns the value and writes the counts
  Vec3 measure(const Vec3& truth, Random& rng, std::array<std::int32_t, 3>& counts) {
    Vec3 out;
    for (int i = 0; i < 3; ++i) {
      double white = 0;
      if (bias_sigma > 0) bias[i] = bias_phi * bias[i] + bias_sigma * rng.normal();
      if (white_sigma > 0) white = white_sigma * rng.normal();
      const double m = scale * (truth[i] + turn_on_bias[i] + bias[i] + white);
      // saturated before the conversion: a crash can read far beyond the range
      const double scaled = std::clamp(m / lsb, -max_count, max_count);
      const std::int64_t c = roundCounts(scaled);
      counts[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(c);
      out[i] = static_cast<double>(c) * lsb;
    }
    return out;
  }
};

}  // namespace

class ImuSensor final : public SensorOf<ImuMeasurement>, public VariationInterface {
 public:
  static constexpr const char* kDoc = "accelerometer and gyroscope with noise, bias, scale, quantisation and range";
  static constexpr ssx_plugin_param kParameters[] = {
      param::text("node", "", "physic node the IMU sits on (default: the first root)"),
      param::flag("noise", "true", "false turns every stochastic term off"),
      param::real("gyro_noise_density", "3.394e-4", "rad/s/sqrt(Hz)", param::nonNegative(), "gyroscope white noise"),
      param::real("gyro_bias_random_walk", "3.8785e-5", "rad/s^2/sqrt(Hz)", param::nonNegative(),
                  "gyroscope bias random walk"),
      param::real("gyro_bias_correlation_time", "1000", "s", param::positive(), "gyroscope bias correlation time"),
      param::real("gyro_turn_on_bias", "8.7e-3", "rad/s", param::nonNegative(),
                  "standard deviation of the gyroscope's turn-on bias"),
      param::real("gyro_scale", "1", "", param::positive(), "gyroscope scale factor"),
      param::real("gyro_lsb", "0.0006981317007977319", "rad/s", param::positive(),
                  "gyroscope resolution, one count (0.04 deg/s)"),
      param::real("gyro_range", "17.453292519943293", "rad/s", param::positive() & param::atMost(1000),
                  "gyroscope full scale (1000 deg/s)"),
      param::real("accel_noise_density", "4.0e-3", "m/s^2/sqrt(Hz)", param::nonNegative(),
                  "accelerometer white noise"),
      param::real("accel_bias_random_walk", "6.0e-3", "m/s^3/sqrt(Hz)", param::nonNegative(),
                  "accelerometer bias random walk"),
      param::real("accel_bias_correlation_time", "300", "s", param::positive(),
                  "accelerometer bias correlation time"),
      param::real("accel_turn_on_bias", "0.196", "m/s^2", param::nonNegative(),
                  "standard deviation of the accelerometer's turn-on bias"),
      param::real("accel_scale", "1", "", param::positive(), "accelerometer scale factor"),
      param::real("accel_lsb", "0.008168939449999999", "m/s^2", param::positive(),
                  "accelerometer resolution, one count (0.833 mg)"),
      param::real("accel_range", "176.5197", "m/s^2", param::positive() & param::atMost(10000),
                  "accelerometer full scale (18 g)"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    const PhysicNode& node = context.artifact->nodeFromParameter(params);
    if (node.isStatic()) throw params.error("an IMU needs a dynamic node");
    // at most 24 bits of counts, as the finest MEMS IMUs (most have 16): what reads the counts
    // (the quadrotor's integer inner loop squares and sums them in 64 bits) can rely on it
    for (const char* prefix : {"gyro_", "accel_"}) {
      const std::string range = std::string(prefix) + "range", lsb = std::string(prefix) + "lsb";
      const double counts = params.get<double>(range) / params.get<double>(lsb);
      if (counts > kMaxCounts) {
        char text[32];
        std::snprintf(text, sizeof text, "%.3g", counts);
        throw params.errorAt(lsb, range + " / " + lsb + " must be at most 2^24 counts (" + text + " here): make " +
                                      lsb + " larger");
      }
    }
  }

  void configure(const Descriptor& params, PluginSetup& /*setup*/) override {
    node_ = &artifact().nodeFromParameter(params);
    const bool noise = params.get<bool>("noise");
    gyro_.read(params, "gyro_");
    accel_.read(params, "accel_");
    const double dt = toSeconds(periodSteps() * environment().timestep());
    gyro_.prepare(dt, noise, random());
    accel_.prepare(dt, noise, random());
    gravity_ = environment().settings().physics.gravity;
    output().accelerometer_lsb = accel_.lsb;
    output().gyroscope_lsb = gyro_.lsb;
  }

  // the bias walks and turn-on biases, and the last reading
  void saveState(StateWriter& out) const override {
    for (const Channel* c : {&gyro_, &accel_}) {
      out.write(c->turn_on_bias);
      out.write(c->bias);
    }
    save(out, value());
  }
  void loadState(StateReader& in) override {
    for (Channel* c : {&gyro_, &accel_}) {
      in.read(c->turn_on_bias);
      in.read(c->bias);
    }
    load(in, output());
  }

  void sense(const StepInfo& info) override {
    const BodyState s = node_->state();
    const Quat to_imu = s.pose.orientation.conjugate();
    ImuMeasurement& m = output();
    m.stamp = info.time;
    m.gyroscope = gyro_.measure(to_imu * s.angular_velocity, random(), m.gyroscope_counts);
    m.accelerometer = accel_.measure(to_imu * (s.linear_acceleration - gravity_), random(), m.accelerometer_counts);
  }

  // domain randomisation (ssx/variation.hpp): how noisy this unit is
  std::span<const Variable> variables() const override {
    static constexpr Variable kVariables[] = {
        {"gyro_noise", 1.0, 0.0, 100.0, "factor on the gyroscope's white noise and bias random walk"},
        {"accel_noise", 1.0, 0.0, 100.0, "factor on the accelerometer's white noise and bias random walk"},
    };
    return kVariables;
  }
  void vary(std::size_t k, double value) override { (k == 0 ? gyro_ : accel_).noiseFactor(value); }

 private:
  const PhysicNode* node_ = nullptr;
  Channel gyro_, accel_;
  Vec3 gravity_ = Vec3::Zero();
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::ImuSensor, "imu"));
