// The scene model as a value: poses from what files write, swarm members' names, and the model
// printed back to scene XML (which is also how two models compare).
#include <ssx/scene_model.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace ssx {

namespace fs = std::filesystem;

Pose poseFromXyzRpy(const Vec3& xyz, const Vec3& rpy) {
  Pose p;
  p.position = xyz;
  p.orientation = Quat(Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                       Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()));
  return p;
}

Pose PlacementModel::pose() const { return poseFromXyzRpy(xyz, rpy); }

std::string PlacementModel::memberName(std::int64_t k) const {
  std::string out = name;
  const std::string index = std::to_string(first_index + k);
  for (auto at = out.find("{i}"); at != std::string::npos; at = out.find("{i}", at + index.size()))
    out.replace(at, 3, index);
  return out;
}

namespace {

// numbers in the fewest digits that read back bit for bit
std::string num(double v) {
  char text[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;
}
std::string num(float v) {
  char text[40];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, static_cast<double>(v));
    if (std::strtof(text, nullptr) == v) break;
  }
  return text;
}
std::string num(std::int64_t v) { return std::to_string(v); }
std::string vec(const Vec3& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }
std::string color(const Color& c) { return num(c[0]) + " " + num(c[1]) + " " + num(c[2]) + " " + num(c[3]); }
std::string seconds(Nanoseconds ns) { return num(toSeconds(ns)); }
std::string path(const fs::path& p) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(p, ec);
  return (ec ? p : absolute).lexically_normal().string();
}

std::string escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// one element: <name a="v" ...> children </name>, or <name .../> without children
class Element {
 public:
  Element(std::ostringstream& out, std::string name, int depth) : out_(out), name_(std::move(name)), depth_(depth) {
    out_ << std::string(2 * static_cast<std::size_t>(depth_), ' ') << '<' << name_;
  }
  Element& operator()(const std::string& key, const std::string& value) {
    out_ << ' ' << key << "=\"" << escaped(value) << '"';
    return *this;
  }
  void attributes(const Descriptor& d) {
    for (const auto& a : d.attributes()) (*this)(a.key, a.value);
  }
  // ends the start tag; the children come next, then close()
  void open() { out_ << ">\n"; }
  void close() { out_ << std::string(2 * static_cast<std::size_t>(depth_), ' ') << "</" << name_ << ">\n"; }
  void end() { out_ << "/>\n"; }

 private:
  std::ostringstream& out_;
  std::string name_;
  int depth_;
};

// a Descriptor as written
void verbatim(std::ostringstream& out, const Descriptor& d, int depth) {
  Element e(out, d.name(), depth);
  e.attributes(d);
  if (d.children().empty()) {
    e.end();
    return;
  }
  e.open();
  for (const Descriptor& c : d.children()) verbatim(out, c, depth + 1);
  e.close();
}

void plugin(Element& e, const PluginDeclaration& p) {
  e("plugin", p.plugin)("class", p.class_name)("period", num(p.period));
  e.attributes(p.params);
}

void overrides(std::ostringstream& out, const PlacementModel& p, Element& e) {
  const bool any = p.driver != nullptr || p.ghost ||
                   std::any_of(p.sensors.begin(), p.sensors.end(), [](const auto& s) { return s != nullptr; });
  if (!any) {
    e.end();
    return;
  }
  e.open();
  if (p.driver != nullptr) verbatim(out, *p.driver, 2);
  for (const auto& s : p.sensors)
    if (s != nullptr) verbatim(out, *s, 2);
  if (p.ghost)
    Element(out, "ghost", 2)("timeout", num(p.ghost->timeout))("horizon", num(p.ghost->horizon))(
        "capacity", num(static_cast<double>(p.ghost->capacity)))
        .end();
  e.close();
}

void environment(std::ostringstream& out, const SceneModel& m) {
  const EnvironmentSettings& s = m.settings;
  Element e(out, "environment", 1);
  e("timestep", seconds(s.timestep))("seed", std::to_string(s.seed))(
      "threads", s.threads == 0 ? std::string("auto") : std::to_string(s.threads))(
      "realtime_factor", num(m.run.realtime_factor))(
      "overrun", m.run.overrun == RunOptions::Overrun::Resync ? "resync" : "catchup");
  if (m.duration) e("duration", seconds(*m.duration));
  e.end();
}

void physics(std::ostringstream& out, const PhysicsSettings& p) {
  Element e(out, "physics", 1);
  e("engine", p.engine)("gravity", vec(p.gravity))("substeps", num(std::int64_t{p.substeps}))(
      "friction", num(p.friction))("restitution", num(p.restitution))("max_linear_speed", num(p.max_linear_speed))(
      "max_angular_speed", num(p.max_angular_speed));
  // the engine's own settings, in its declarations' order
  if (const PhysicEngineClass* c = findPhysicEngine(p.engine)) {
    Descriptor values = p.options;
    if (c->describe) c->describe(p, values);
    for (const ssx_plugin_param& s : c->settings)
      if (const auto* a = values.find(s.name)) e(s.name, a->value);
  }
  e.end();
}

void render(std::ostringstream& out, const RenderSettings& r) {
  Element e(out, "render", 1);
  e("engine", r.engine)("rate_hz", num(r.rate_hz))("period", num(r.period_steps))(
      "width", num(std::int64_t{r.width}))("height", num(std::int64_t{r.height}))("background", color(r.background))(
      "shadows", r.shadows ? "true" : "false")("time_stamp", r.time_stamp ? "true" : "false");
  if (r.cameras.empty()) {
    e.end();
    return;
  }
  e.open();
  for (const CameraSpec& c : r.cameras) {
    Element cam(out, "camera", 2);
    cam("name", c.name);
    if (!c.frame_scene) cam("xyz", vec(c.position));
    cam("look_at", vec(c.look_at));
    if (!c.follow.empty()) cam("follow", c.follow);
    cam("fov_deg", num(c.fov_deg));
    if (!c.frames_dir.empty()) cam("frames", c.frames_dir.string());
    if (!c.video.empty()) cam("video", c.video.string());
    if (!c.snapshot.empty()) cam("snapshot", c.snapshot.string());
    cam.end();
  }
  e.close();
}

void wind(std::ostringstream& out, const WindSettings& w) {
  Element e(out, "wind", 1);
  e("mean", vec(w.mean))("gust", vec(w.gust))("gust_start", num(w.gust_start))("gust_duration", num(w.gust_duration))(
      "turbulence_w20", num(w.turbulence_w20))("turbulence_min_airspeed", num(w.turbulence_min_airspeed));
  e.end();
}

void obstacleShape(std::ostringstream& out, const ShapeModel& m) {
  const Shape& s = m.shape;
  static constexpr const char* kNames[] = {"box", "sphere", "cylinder", "capsule", "plane", "mesh"};
  Element e(out, kNames[static_cast<int>(s.kind)], 2);
  if (s.kind == Shape::Kind::Box) e("size", vec(s.size));
  if (s.kind == Shape::Kind::Sphere || s.kind == Shape::Kind::Cylinder || s.kind == Shape::Kind::Capsule)
    e("radius", num(s.radius));
  if (s.kind == Shape::Kind::Cylinder || s.kind == Shape::Kind::Capsule) e("length", num(s.length));
  e("xyz", vec(m.xyz))("rpy", vec(m.rpy))("density", num(s.density));
  e.end();
}

void placement(std::ostringstream& out, const PlacementModel& p) {
  switch (p.kind) {
    case PlacementModel::Kind::Artifact: {
      Element e(out, "artifact", 1);
      e("name", p.name)("type", p.type)("xyz", vec(p.xyz))("rpy", vec(p.rpy));
      if (p.allow_overlap) e("allow_overlap", "true");
      if (!p.present) e("present", "false");
      overrides(out, p, e);
      break;
    }
    case PlacementModel::Kind::Swarm: {
      Element e(out, "swarm", 1);
      e("type", p.type)("count", num(p.count))("name", p.name)("first_index", num(p.first_index))(
          "layout", p.layout)("xyz", vec(p.xyz))("rpy", vec(p.rpy));
      if (p.layout == "grid") e("spacing", num(p.spacing))("columns", num(p.columns))("rows", num(p.rows));
      if (p.layout == "random") e("min", vec(p.min))("max", vec(p.max))("min_distance", num(p.min_distance));
      if (p.layout == "sphere") e("radius", num(p.radius));
      if (p.random_yaw) e("random_yaw", "true");
      if (p.allow_overlap) e("allow_overlap", "true");
      if (!p.present) e("present", "false");
      overrides(out, p, e);
      break;
    }
    case PlacementModel::Kind::Ground:
      Element(out, "ground", 1)("z", num(p.xyz.z())).end();
      break;
    case PlacementModel::Kind::Obstacle: {
      Element e(out, "obstacle", 1);
      e("name", p.name)("xyz", vec(p.xyz))("rpy", vec(p.rpy))("color", color(p.color));
      if (p.allow_overlap) e("allow_overlap", "true");
      e.open();
      for (const ShapeModel& m : p.shapes) obstacleShape(out, m);
      e.close();
      break;
    }
  }
}

}  // namespace

std::string SceneModel::toXml() const {
  std::ostringstream out;
  out << "<scene>\n";
  environment(out, *this);
  physics(out, settings.physics);
  render(out, settings.render);
  wind(out, settings.wind);
  for (const fs::path& dir : plugin_dirs) Element(out, "plugin_path", 1)("dir", path(dir)).end();
  for (const ExtensionModel& x : extensions) {
    Element e(out, "extension", 1);
    e("name", x.name);
    plugin(e, x.plugin);
    e.end();
  }
  for (const auto& [name, type] : types) {
    Element e(out, "type", 1);
    e("name", name)("file", path(type.file));
    if (!type.type_driver && type.type_sensors.empty() && type.type_joints.empty()) {
      e.end();
      continue;
    }
    e.open();
    for (const Descriptor& j : type.type_joints) verbatim(out, j, 2);
    if (type.type_driver) {
      Element d(out, "driver", 2);
      plugin(d, *type.type_driver);
      d.end();
    }
    for (const PluginDeclaration& p : type.type_sensors) {
      Element d(out, "sensor", 2);
      plugin(d, p);
      d.end();
    }
    e.close();
  }
  for (const PlacementModel& p : placements) placement(out, p);
  out << "</scene>\n";
  return out.str();
}

bool operator==(const SceneModel& a, const SceneModel& b) { return a.toXml() == b.toXml(); }

}  // namespace ssx
