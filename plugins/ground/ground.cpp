// ground: the floor's colour under a robot (ssx::GroundMeasurement), as an e-puck's or foot-bot's
// ground sensors read it: at each of `points` (x y in the node's frame, projected straight down),
// the colour of the floor there and its grey level (0 black .. 1 white, ITU-R 601 luma). The floor
// is `floor` (a colour) painted with `regions`, later ones over earlier ones:
//   circle CX CY R  RED GREEN BLUE      a disc of radius R (m) centred at (CX, CY)
//   rect X0 Y0 X1 Y1  RED GREEN BLUE    an axis-aligned rectangle
// separated by ';', colours 0..1, world frame. `noise` adds Gaussian noise to each grey level,
// kept within [0, 1].
//
// Parameters: kParameters below, or `ssx plugins --params ground`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace ssx::plugins {

namespace {

struct Region {
  bool circle = true;
  double a = 0, b = 0, c = 0, d = 0;  // circle: cx, cy, r; rect: x0, y0, x1, y1
  Vec3 color = Vec3::Zero();
  bool contains(double x, double y) const {
    if (circle) return (x - a) * (x - a) + (y - b) * (y - b) <= c * c;
    return x >= std::min(a, c) && x <= std::max(a, c) && y >= std::min(b, d) && y <= std::max(b, d);
  }
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\n\r");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\n\r") - b + 1);
}

// calls read(item) for each non-empty item of a ';'-separated list, until one returns false
template <class Read>
void forEachItem(const std::string& text, Read&& read) {
  std::stringstream all(text);
  std::string item;
  while (std::getline(all, item, ';')) {
    item = trim(item);
    if (!item.empty() && !read(item)) return;
  }
}

// the regions as written, or a message saying what is wrong with the first that is not right
std::vector<Region> parseRegions(const std::string& text, std::string& error) {
  std::vector<Region> out;
  forEachItem(text, [&](const std::string& item) {
    std::istringstream in(item);
    std::string kind;
    in >> kind;
    Region r;
    r.circle = kind == "circle";
    if (kind != "circle" && kind != "rect") {
      error = "a region is 'circle CX CY R RED GREEN BLUE' or 'rect X0 Y0 X1 Y1 RED GREEN BLUE', got '" + item + "'";
      return false;
    }
    double v[7];
    const int n = r.circle ? 6 : 7;
    for (int k = 0; k < n; ++k) in >> v[k];
    std::string rest;
    if (in.fail() || (in >> rest)) {
      error = "region '" + item + "' needs " + std::to_string(n) + " numbers after '" + kind + "'";
      return false;
    }
    r.a = v[0];
    r.b = v[1];
    r.c = v[2];
    if (!r.circle) r.d = v[3];
    r.color = Vec3(v[n - 3], v[n - 2], v[n - 1]);
    if (!(r.color.array() >= 0).all() || !(r.color.array() <= 1).all() || (r.circle && !(r.c > 0))) {
      error = "region '" + item + "': colours are within 0..1 and a circle's radius is positive";
      return false;
    }
    out.push_back(r);
    return true;
  });
  if (!error.empty()) out.clear();
  return out;
}

std::vector<Vec3> parsePoints(const std::string& text, std::string& error) {
  std::vector<Vec3> out;
  forEachItem(text, [&](const std::string& item) {
    std::istringstream in(item);
    double x = 0, y = 0;
    std::string rest;
    in >> x >> y;
    if (in.fail() || (in >> rest)) {
      error = "a point is 'X Y' (m, in the node's frame), got '" + item + "'";
      return false;
    }
    out.push_back(Vec3(x, y, 0));
    return true;
  });
  if (!error.empty()) out.clear();
  if (out.empty() && error.empty()) error = "give at least one point";
  return out;
}

}  // namespace

class GroundSensor final : public SensorOf<GroundMeasurement> {
 public:
  static constexpr const char* kDoc = "the floor's colour under the robot, from colour regions of the scene";
  static constexpr ssx_plugin_param kParameters[] = {
      param::text("points", "0 0", "where it looks, 'X Y' in the node's frame (m), separated by ';'"),
      param::vec3("floor", "1 1 1", "", param::between(0, 1), "the floor's colour where no region is (RGB 0..1)"),
      param::text("regions", "", "'circle CX CY R RED GREEN BLUE' or 'rect X0 Y0 X1 Y1 RED GREEN BLUE' (m, world), ';' between"),
      param::real("noise", "0", "", param::between(0, 1), "standard deviation of each grey level"),
      param::text("node", "", "physic node it is fixed to (default: the first root)"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    std::string error;
    (void)parsePoints(params.get<std::string>("points"), error);
    if (!error.empty()) throw params.errorAt("points", error);
    (void)parseRegions(params.get<std::string>("regions", ""), error);
    if (!error.empty()) throw params.errorAt("regions", error);
    (void)context.artifact->nodeFromParameter(params, "node");
  }

  void configure(const Descriptor& params, PluginSetup&) override {
    std::string error;
    points_ = parsePoints(params.get<std::string>("points"), error);
    regions_ = parseRegions(params.get<std::string>("regions", ""), error);
    floor_ = params.get<Vec3>("floor");
    noise_ = params.get<double>("noise");
    node_ = &artifact().nodeFromParameter(params, "node");
    output().colors.assign(points_.size(), Vec3::Zero());
    output().readings.assign(points_.size(), 0.0);
  }

  void sense(const StepInfo&) override {
    const Pose pose = node_->pose();
    GroundMeasurement& m = output();
    for (std::size_t k = 0; k < points_.size(); ++k) {
      const Vec3 p = pose.transformPoint(points_[k]);
      Vec3 color = floor_;
      for (const Region& r : regions_)
        if (r.contains(p.x(), p.y())) color = r.color;
      m.colors[k] = color;
      double grey = 0.299 * color.x() + 0.587 * color.y() + 0.114 * color.z();
      if (noise_ > 0) grey += random().normal(0.0, noise_);
      m.readings[k] = std::clamp(grey, 0.0, 1.0);
    }
  }

  void saveState(StateWriter& out) const override {
    const auto& m = static_cast<const GroundMeasurement&>(latest());
    for (std::size_t k = 0; k < points_.size(); ++k) {
      out.write(m.colors[k]);
      out.write(m.readings[k]);
    }
  }
  void loadState(StateReader& in) override {
    GroundMeasurement& m = output();
    for (std::size_t k = 0; k < points_.size(); ++k) {
      in.read(m.colors[k]);
      in.read(m.readings[k]);
    }
  }

 private:
  std::vector<Vec3> points_;
  std::vector<Region> regions_;
  Vec3 floor_ = Vec3::Ones();
  double noise_ = 0;
  const PhysicNode* node_ = nullptr;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::GroundSensor, "ground"));
