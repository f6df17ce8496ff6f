// foraging: the nest and the items of a central-place foraging run, as ARGoS's foraging loop
// functions keep them. After each step, every item that lies in the nest (its centre within the
// `nest` circle) and that nobody holds (PhysicNode::attachments) counts as delivered and is put
// back at a random place of `area`, at rest, where no other item or robot is within `clearance`;
// the count is a metric (items_delivered, items_per_minute) and is logged when the run ends.
//
// Parameters: kParameters below, or `ssx plugins --params foraging`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/hash.hpp>
#include <ssx/metrics.hpp>
#include <ssx/plugin_abi.hpp>
#include <ssx/random.hpp>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

namespace ssx::plugins {

class Foraging final : public SimulationExtension, public MetricSource {
 public:
  static constexpr const char* kDoc = "counts items delivered to a nest and puts them back in the foraging area";
  static constexpr ssx_plugin_param kParameters[] = {
      param::text("items", "item", "the items: every artifact whose name starts with this"),
      param::required(param::vec3("nest", "", "m", param::between(-1e6, 1e6), "the nest: 'X Y RADIUS', a circle on the floor (world)")),
      param::required(param::text("area", "", "where delivered items go back: 'X0 Y0 X1 Y1' (m, world)")),
      param::real("clearance", "0.1", "m", param::nonNegative(), "no item or robot within this of where one is put back"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    (void)area(params);
    if (!(params.get<Vec3>("nest").z() > 0)) throw params.errorAt("nest", "the nest's radius must be positive");
    if (items(*context.environment, params).empty())
      throw params.errorAt("items", "no artifact with a dynamic root has a name starting with '" +
                                        params.get<std::string>("items") + "'");
  }

  void init(Environment& env, const Descriptor& params) override {
    const Vec3 nest = params.get<Vec3>("nest");
    nest_ = Vec3(nest.x(), nest.y(), 0);
    radius_ = nest.z();
    const auto a = area(params);
    lo_ = Vec3(a[0], a[1], 0);
    hi_ = Vec3(a[2], a[3], 0);
    clearance_ = params.get<double>("clearance");
    items_ = items(env, params);
    random_ = Random(fnv1a("foraging", env.settings().seed));
  }

  void afterStep(Environment& env) override {
    minutes_ = toSeconds(env.time()) / 60;
    for (Artifact* item : items_) {
      PhysicNode& root = item->root();
      const Vec3 p = root.pose().position;
      if (Vec3(p.x() - nest_.x(), p.y() - nest_.y(), 0).norm() > radius_ || root.attachments() > 0) continue;
      ++delivered_;
      BodyState s = env.bodyState(root.bodyIndex());
      const Vec3 offset = s.pose.position - p;  // (centre of mass from the root's origin)
      s.pose.position = place(env, p.z()) + offset;
      s.linear_velocity = Vec3::Zero();
      s.angular_velocity = Vec3::Zero();
      env.setBodyState(root.bodyIndex(), s);
    }
  }

  void shutdown(Environment& env) override {
    const double minutes = toSeconds(env.time()) / 60;
    char line[160];
    std::snprintf(line, sizeof line, "foraging: %lld items delivered in %.1f s (%.2f per minute)",
                  static_cast<long long>(delivered_), toSeconds(env.time()),
                  minutes > 0 ? static_cast<double>(delivered_) / minutes : 0.0);
    env.log(LogLevel::Info, line);
  }

  std::vector<std::string> metricNames() const override { return {"items_delivered", "items_per_minute"}; }
  void metrics(std::vector<Metric>& out) const override {
    out.push_back({"items_delivered", static_cast<double>(delivered_)});
    out.push_back({"items_per_minute", minutes_ > 0 ? static_cast<double>(delivered_) / minutes_ : std::nan("")});
  }

  void saveState(StateWriter& out) const override {
    out.write(delivered_);
    random_.save(out);
  }
  void loadState(StateReader& in) override {
    in.read(delivered_);
    random_.load(in);
  }

 private:
  static std::vector<double> area(const Descriptor& params) {
    std::istringstream in(params.get<std::string>("area"));
    std::vector<double> v;
    for (double x = 0; in >> x;) v.push_back(x);
    if (v.size() != 4 || !in.eof() || !(v[0] < v[2]) || !(v[1] < v[3]))
      throw params.errorAt("area", "give 'X0 Y0 X1 Y1' with X0 < X1 and Y0 < Y1 (m)");
    return v;
  }

  template <class Env>  // Environment, or const Environment (validate)
  static std::vector<std::conditional_t<std::is_const_v<Env>, const Artifact*, Artifact*>> items(Env& env,
                                                                                                const Descriptor& params) {
    const std::string prefix = params.get<std::string>("items");
    std::vector<std::conditional_t<std::is_const_v<Env>, const Artifact*, Artifact*>> out;
    for (std::size_t i = 0; i < env.artifactCount(); ++i) {
      auto& a = env.artifact(i);
      if (a.name().starts_with(prefix) && a.rootCount() > 0 && !a.root().isStatic()) out.push_back(&a);
    }
    return out;
  }

  // a random place in the area away from every other dynamic artifact (the best of 20 tries)
  Vec3 place(const Environment& env, double z) {
    Vec3 best = lo_;
    double best_gap = -1;
    for (int attempt = 0; attempt < 20 && best_gap < clearance_; ++attempt) {
      const Vec3 p(random_.uniform(lo_.x(), hi_.x()), random_.uniform(lo_.y(), hi_.y()), z);
      double gap = 1e300;
      for (std::size_t i = 0; i < env.artifactCount(); ++i) {
        const Artifact& a = env.artifact(i);
        if (a.rootCount() == 0 || a.root().isStatic()) continue;
        const Vec3 q = a.root().pose().position;
        gap = std::min(gap, std::hypot(q.x() - p.x(), q.y() - p.y()));
      }
      if (gap > best_gap) {
        best = p;
        best_gap = gap;
      }
    }
    return best;
  }

  Vec3 nest_ = Vec3::Zero(), lo_ = Vec3::Zero(), hi_ = Vec3::Zero();
  double radius_ = 0, clearance_ = 0, minutes_ = 0;
  std::vector<Artifact*> items_;
  std::int64_t delivered_ = 0;
  Random random_;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_EXTENSION(ssx::plugins::Foraging, "foraging"));
