// range: the robots and obstacles around an artifact (ssx::RangeMeasurement), nearest first.
//
// Robots come from the environment's neighbour index (its first dynamic root's position);
// obstacles are the shapes of static artifacts (boxes, spheres, cylinders, capsules; not planes),
// seen at their nearest surface point.
//
// Parameters: kParameters below, or `ssx plugins --params range`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

namespace ssx::plugins {

using ObstacleShape = Environment::StaticShape;

class RangeSensor final : public SensorOf<RangeMeasurement> {
 public:
  static constexpr const char* kDoc = "robots and obstacles around an artifact, nearest first";
  static constexpr ssx_plugin_param kParameters[] = {
      param::real("range", "2.5", "m", param::positive(), "how far it sees"),
      param::choice("frame", "world", "world body", "frame of the relative positions"),
      param::real("position_noise", "0", "m", param::nonNegative(),
                  "standard deviation per axis of Gaussian noise on each relative position"),
      param::real("fov_deg", "360", "deg", param::positive() & param::atMost(360),
                  "full cone angle around the body x axis; 360 sees all around"),
      param::integer("max_count", "0", param::nonNegative(), "keep at most this many detections, nearest first; 0 keeps all"),
      param::flag("obstacles", "true", "false ignores static obstacles"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    if (context.artifact->rootCount() == 0 || context.artifact->root().isStatic())
      throw params.error("a range sensor needs a dynamic root");
  }

  void configure(const Descriptor& params, PluginSetup& setup) override {
    range_ = params.get<double>("range");
    output().body_frame = params.get<std::string>("frame") == "body";
    noise_ = params.get<double>("position_noise");
    const double fov = params.get<double>("fov_deg");
    cos_half_fov_ = fov >= 360 ? -2.0 : std::cos(fov / 2 * std::numbers::pi / 180.0);
    max_count_ = static_cast<std::size_t>(params.get<std::int64_t>("max_count"));

    const Environment& env = environment();
    setup.enableNeighborQueries(range_);
    // the environment's obstacles, listed once for every range sensor (a block each would be one
    // more cache miss per robot and step)
    if (params.get<bool>("obstacles"))
      obstacles_ = setup.shared<Obstacles>("obstacles", [&env] {
        Obstacles list;
        for (const ObstacleShape& o : env.staticShapes())
          if (o.shape.kind != Shape::Kind::Plane) list.push_back(&o);
        return list;
      });
    // room for what a robot usually sees, so that sensing allocates nothing; a robot that sees
    // more grows these once, to the most it has seen
    const std::size_t typical = std::min<std::size_t>(16, env.artifactCount() + obstacles().size());
    output().detections.reserve(typical);
  }

  void saveState(StateWriter& out) const override { save(out, value()); }
  void loadState(StateReader& in) override { load(in, output()); }

  void sense(const StepInfo& info) override {
    RangeMeasurement& m = output();
    m.stamp = info.time;
    m.detections.clear();
    const Pose self = artifact().root().pose();
    const Quat to_body = self.orientation.conjugate();
    auto visible = [&](const Vec3& rel) {
      if (cos_half_fov_ < -1.0) return true;
      const double d = rel.norm();
      return d > 0 && (to_body * rel).x() / d >= cos_half_fov_;
    };
    // robots, in the index's order (the sort below orders them)
    const std::size_t own = artifact().index();
    environment().forEachNeighbor(self.position, range_, [&](std::size_t j, const Vec3& position) {
      if (j == own) return;
      const Vec3 rel = position - self.position;
      if (visible(rel)) m.detections.push_back({rel, rel.norm(), j, false});
    });
    // obstacles, at their nearest point
    for (const ObstacleShape* o : obstacles()) {
      const Vec3 rel = nearestSurfacePoint(o->shape, o->world, self.position) - self.position;
      const double d = rel.norm();
      if (d <= range_ && visible(rel)) m.detections.push_back({rel, d, o->artifact, true});
    }
    // nearest first; ties by artifact, then (two shapes of one obstacle) by where: a total order,
    // so the result does not depend on the order the index visited the robots in
    std::sort(m.detections.begin(), m.detections.end(), [](const auto& a, const auto& b) {
      if (a.distance != b.distance) return a.distance < b.distance;
      if (a.artifact != b.artifact) return a.artifact < b.artifact;
      return std::lexicographical_compare(a.relative.begin(), a.relative.end(), b.relative.begin(), b.relative.end());
    });
    if (max_count_ > 0 && m.detections.size() > max_count_) m.detections.resize(max_count_);
    // frame and noise, drawn in a fixed order
    for (auto& d : m.detections) {
      if (noise_ > 0)
        for (int k = 0; k < 3; ++k) d.relative[k] += noise_ * random().normal();
      if (m.body_frame) d.relative = to_body * d.relative;
    }
  }

 private:
  double range_ = 2.5, noise_ = 0, cos_half_fov_ = -2;
  std::size_t max_count_ = 0;
  using Obstacles = std::vector<const ObstacleShape*>;  // owned by the environment
  std::shared_ptr<const Obstacles> obstacles_;         // none when obstacles="false"
  const Obstacles& obstacles() const {
    static const Obstacles none;
    return obstacles_ != nullptr ? *obstacles_ : none;
  }
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::RangeSensor, "range"));
