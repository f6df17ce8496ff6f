// proximity: a ring of infrared proximity sensors (ssx::ProximityMeasurement): rays cast in the
// node's horizontal plane against every shape but the robot's own, with the physics engine's ray
// queries (ODE's ray geoms, Bullet's ray tests).
//
// A ray that meets something d metres out reads the response curve at d: "argos" exp(-d) (ARGoS's
// proximity sensor), "linear" 1 - d/range; nothing within range reads 0. `noise` adds uniform
// noise in [-noise, noise] to every reading, then readings are kept within [0, 1] (as ARGoS does).
//
// Parameters: kParameters below, or `ssx plugins --params proximity`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <vector>

namespace ssx::plugins {

class ProximitySensor final : public SensorOf<ProximityMeasurement> {
 public:
  static constexpr const char* kDoc = "a ring of infrared proximity sensors: rays cast with the physics engine";
  static constexpr ssx_plugin_param kParameters[] = {
      param::integer("count", "8", param::between(1, 1024), "rays, evenly spaced from straight ahead (when no angles)"),
      param::text("angles", "", "each ray's direction, deg from the node's x axis toward y, separated by spaces"),
      param::real("range", "0.1", "m", param::positive() & param::atMost(1000), "how far a ray reaches"),
      param::real("radius", "0", "m", param::nonNegative() & param::atMost(1000),
                  "the sensors sit this far from the node's z axis (the robot's body radius): distances are from there, anything nearer reads 0"),
      param::real("height", "0", "m", param::between(-1000, 1000), "rays lie this far above the node's origin"),
      param::choice("response", "argos", "argos linear", "argos: exp(-d) (ARGoS's); linear: 1 - d/range"),
      param::real("noise", "0", "", param::between(0, 1), "uniform noise in [-noise, noise] added to each reading"),
      param::text("node", "", "physic node the rays are fixed to (default: the first root)"),
  };

  static std::vector<double> angles(const Descriptor& params) {
    const std::string text = params.get<std::string>("angles", "");
    std::vector<double> out;
    if (text.empty()) {
      const auto n = params.get<std::int64_t>("count");
      for (std::int64_t k = 0; k < n; ++k) out.push_back(2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n));
      return out;
    }
    std::istringstream in(text);
    double deg = 0;
    while (in >> deg) {
      if (!std::isfinite(deg)) break;
      out.push_back(deg * std::numbers::pi / 180.0);
    }
    if (!in.eof() || out.empty())
      throw params.errorAt("angles", "angles must be numbers in degrees separated by spaces, got '" + text + "'");
    return out;
  }

  static void validate(const Descriptor& params, const PluginContext& context) {
    (void)angles(params);
    (void)context.artifact->nodeFromParameter(params, "node");
  }

  void configure(const Descriptor& params, PluginSetup& setup) override {
    const std::vector<double> a = angles(params);
    range_ = params.get<double>("range");
    linear_ = params.get<std::string>("response") == "linear";
    noise_ = params.get<double>("noise");
    node_ = &artifact().nodeFromParameter(params, "node");
    radius_ = params.get<double>("radius");
    const double height = params.get<double>("height");
    // each ray is cast from the node's axis, its first `radius` inside the robot (its own shapes
    // are not hit): what is closer than the radius (a wall the robot is pressed against, whose
    // face a ray starting at the radius would start behind) reads as touching
    for (const double angle : a) {
      starts_.push_back(Vec3(0, 0, height));
      directions_.push_back(Vec3(std::cos(angle), std::sin(angle), 0));
    }
    rays_.resize(a.size());
    hits_.resize(a.size());
    output().readings.assign(a.size(), 0.0);
    output().distances.assign(a.size(), std::numeric_limits<double>::infinity());
    output().angles = a;
    output().range = range_;
    output().radius = radius_;
    setup.enableRayQueries();
  }

  void sense(const StepInfo& info) override {
    const Pose pose = node_->pose();
    for (std::size_t k = 0; k < rays_.size(); ++k) {
      rays_[k].from = pose.transformPoint(starts_[k]);
      rays_[k].to = rays_[k].from + (radius_ + range_) * (pose.orientation * directions_[k]);
    }
    environment().castRays(rays_, hits_, &artifact());
    ProximityMeasurement& m = output();
    m.stamp = info.time;
    for (std::size_t k = 0; k < rays_.size(); ++k) {
      const bool seen = hits_[k].hit && hits_[k].distance <= radius_ + range_;
      const double d = seen ? std::max(0.0, hits_[k].distance - radius_) : std::numeric_limits<double>::infinity();
      double reading = !seen ? 0.0 : linear_ ? 1.0 - d / range_ : std::exp(-d);
      if (noise_ > 0) reading += random().uniform(-noise_, noise_);
      m.readings[k] = std::clamp(reading, 0.0, 1.0);
      m.distances[k] = d;
    }
  }

  void saveState(StateWriter& out) const override {
    for (double r : latestReadings().readings) out.write(r);
    for (double d : latestReadings().distances) out.write(d);
  }
  void loadState(StateReader& in) override {
    for (double& r : output().readings) in.read(r);
    for (double& d : output().distances) in.read(d);
  }

 private:
  const ProximityMeasurement& latestReadings() const { return static_cast<const ProximityMeasurement&>(latest()); }
  const PhysicNode* node_ = nullptr;
  double range_ = 0, noise_ = 0, radius_ = 0;
  bool linear_ = false;
  std::vector<Vec3> starts_, directions_;  // in the node's frame
  std::vector<Ray> rays_;
  std::vector<RayHit> hits_;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::ProximitySensor, "proximity"));
