// Placements: read from the scene into the model (<artifact>, <swarm> with its layout, <ground>,
// <obstacle> with its shapes); scene/builder.cpp builds them.
#include "scene/xml/layouts.hpp"
#include "scene/xml/scene_loader.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ssx::detail {

// --- reading ---------------------------------------------------------------------------------

void SceneLoader::readPlacements() {
  std::size_t swarm_index = 0;
  for (std::size_t k = 0; k < entities_.size(); ++k) {
    log_.stage = stage(2, 2 * static_cast<std::int64_t>(k));
    const Descriptor& d = *entities_[k].element;
    PlacementModel p;
    p.where = d.where();
    bool ok = true;
    // a name given empty would make an artifact nobody can name: an error, not a silent drop
    for (const char* key : {"name", "type"})
      if (const auto* a = d.find(key); a != nullptr && a->value.empty())
        error(a->where, "<" + d.name() + ">: attribute '" + key + "' is empty; give it a value");
    if (d.name() == "artifact") {
      p.kind = PlacementModel::Kind::Artifact;
      p.name = require(d, "name");
      p.type = require(d, "type");
      p.xyz = read<Vec3>(d, "xyz", Vec3::Zero());
      p.rpy = read<Vec3>(d, "rpy", Vec3::Zero());
      p.allow_overlap = read<bool>(d, "allow_overlap", false);
      p.present = read<bool>(d, "present", true);
      checkUnknown(d, {"driver", "sensor", "ghost"});
      ok = !p.name.empty() && !p.type.empty() && readOverrides(d, p);
    } else if (d.name() == "swarm") {
      p.kind = PlacementModel::Kind::Swarm;
      ok = readSwarm(d, p, swarm_index++);
    } else if (d.name() == "ground") {
      p.kind = PlacementModel::Kind::Ground;
      p.name = "ground";
      p.xyz.z() = read<double>(d, "z", 0.0);
      checkUnknown(d);
    } else {
      p.kind = PlacementModel::Kind::Obstacle;
      ok = readObstacle(d, p);
    }
    if (!ok) continue;
    model_.placements.push_back(std::move(p));
    placement_stage_.push_back(log_.stage);
  }
}

// the type (read now, if it was not yet) and the parameters the placing element sets on its plugins
bool SceneLoader::readOverrides(const Descriptor& d, PlacementModel& p) {
  const ArtifactType* type = artifactType(p.type, d.where());
  // the parameters the element sets, as written, but for a period that is no count of steps
  // (reported here, and the type's used)
  const auto overrides = [&](const Descriptor& o) {
    auto copy = std::make_shared<Descriptor>(o);
    const std::size_t errors_before = errorCount();
    if (o.has("period")) (void)readCount(o, "period", 1, 1);
    if (errorCount() != errors_before) copy->erase("period");
    return std::shared_ptr<const Descriptor>(std::move(copy));
  };
  if (const Descriptor* o = d.child("driver")) p.driver = overrides(*o);
  if (type == nullptr) return true;  // reported; built as far as it goes (its name is still taken)
  p.sensors.assign(type->sensors.size(), nullptr);
  for (const Descriptor* o : d.childrenNamed("sensor")) {
    const std::int64_t i = read<std::int64_t>(*o, "index", 0);
    if (i < 0 || i >= static_cast<std::int64_t>(type->sensors.size())) {
      error(o->where(), "<sensor>: index " + std::to_string(i) + " does not name a sensor of type '" + p.type +
                            "' (it has " + std::to_string(type->sensors.size()) + ")");
      continue;
    }
    p.sensors[static_cast<std::size_t>(i)] = overrides(*o);
  }
  if (p.driver != nullptr && !type->driver)
    error(p.driver->where(), "<driver>: artifact type '" + p.type + "' has no driver to set parameters of");
  if (const Descriptor* g = d.child("ghost")) {
    // a real robot: its poses from outside, interpolated to simulated time (PoseStream)
    PoseStream::Settings s;
    for (auto [key, value] : {std::pair{"timeout", &s.timeout}, std::pair{"horizon", &s.horizon}}) {
      const double v = read<double>(*g, key, *value);
      if (v >= 0 && v <= kMaxDurationSeconds)
        *value = v;
      else
        record(g->errorAt(key, std::string("attribute '") + key + "' must be 0 s or more, got '" + g->find(key)->value + "'"));
    }
    s.capacity = static_cast<std::size_t>(readCount(*g, "capacity", static_cast<std::int64_t>(s.capacity), 2, 1'000'000));
    checkUnknown(*g);
    if (p.driver != nullptr)
      error(p.driver->where(), "<driver>: '" + p.name + "' is a ghost (moved by the poses it is given): it runs no driver");
    p.ghost = s;
    p.ghost_where = g->where();
  }
  return true;
}

void SceneLoader::checkMemory(const Descriptor& d, const PlacementModel& p) {
  // what an artifact costs while it runs, measured (ssx run, 100,000 members, largest resident
  // size): a box 3.5 KiB, an mk_quad (one body, a driver, two sensors) 9 KiB. Estimated on the low
  // side (3 KiB a body, 1.5 KiB a plugin), so that only what cannot fit is refused.
  constexpr double kBytesPerBody = 3 << 10, kBytesPerPlugin = 1536;
  if (p.type.empty()) return;
  const ArtifactType* type = artifactType(p.type, d.where());
  if (type == nullptr) return;
  const double plugins = static_cast<double>(type->sensors.size()) + (type->driver ? 1 : 0);
  const double each = kBytesPerBody * static_cast<double>(std::max<std::size_t>(type->physic.size(), 1)) +
                      kBytesPerPlugin * plugins;
  placed_bytes_ += each * static_cast<double>(p.count);
  const double memory =
      options_.max_memory_bytes > 0
          ? static_cast<double>(options_.max_memory_bytes)
          : static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
  if (memory <= 0 || placed_bytes_ <= memory) return;
  constexpr double kGiB = 1 << 30;
  const double swarm = each * static_cast<double>(p.count);
  char text[240];
  std::snprintf(text, sizeof text, "<swarm>: %lld members of '%s' need about %.3g GiB (%.3g KiB each, estimated",
                static_cast<long long>(p.count), p.type.c_str(), swarm / kGiB, each / 1024);
  std::string message = text;
  if (placed_bytes_ > swarm) {
    std::snprintf(text, sizeof text, "; %.3g GiB with the artifacts before them", placed_bytes_ / kGiB);
    message += text;
  }
  std::snprintf(text, sizeof text, "), more than %s (%.3g GiB): make 'count' smaller",
                options_.max_memory_bytes > 0 ? "the memory allowed" : "this machine's memory", memory / kGiB);
  error(d.where(), message + text);
}

bool SceneLoader::readSwarm(const Descriptor& d, PlacementModel& p, std::size_t swarm_index) {
  const std::size_t errors_before = errorCount();
  p.type = require(d, "type");
  p.count = readCount(d, "count", 1, 1);
  p.name = read<std::string>(d, "name", p.type + "{i}");
  p.first_index = readCount(d, "first_index", 0, 0);
  p.layout = readChoice(d, "layout", "grid", {"grid", "random", "sphere"});
  p.xyz = read<Vec3>(d, "xyz", Vec3::Zero());
  p.rpy = read<Vec3>(d, "rpy", Vec3::Zero());
  const std::int64_t count = p.count;
  checkMemory(d, p);
  if (errorCount() != errors_before) return false;  // (its layout is not worked out)
  if (p.layout == "grid") {
    p.spacing = readPositive(d, "spacing", 1.0);
    p.columns = readCount(d, "columns", static_cast<std::int64_t>(std::ceil(std::sqrt(static_cast<double>(count)))), 1);
    p.rows = readCount(d, "rows", (count + p.columns - 1) / p.columns, 1);
    p.positions = detail::gridLayout(count, p.spacing, p.columns, p.rows);
  } else if (p.layout == "random") {
    p.min = read<Vec3>(d, "min", p.min);
    p.max = read<Vec3>(d, "max", p.max);
    if (!(p.min.array() <= p.max.array()).all()) error(d.where(), "<swarm>: every component of 'min' must be <= 'max'");
    p.min_distance = read<double>(d, "min_distance", 0.0);
    // a stream of its own, from the scene seed and the swarm's position among the swarms
    Random rng(deriveSeed(settings_.seed, 0xa11ce5ULL, swarm_index));
    p.positions = detail::randomLayout(count, p.min, p.max, p.min_distance, rng);
    if (static_cast<std::int64_t>(p.positions.size()) < count) {
      error(d.where(), "<swarm>: could not place " + std::to_string(count) + " members " +
                           std::to_string(p.min_distance) + " m apart in the box: enlarge it or lower min_distance");
      p.positions.resize(static_cast<std::size_t>(count), Vec3::Zero());
    }
  } else {
    p.radius = readPositive(d, "radius", 1.0);
    p.positions = detail::sphereLayout(count, p.radius);
  }
  p.allow_overlap = read<bool>(d, "allow_overlap", false);
  p.present = read<bool>(d, "present", true);
  p.random_yaw = read<bool>(d, "random_yaw", false);
  if (p.random_yaw) {
    // a stream of its own, apart from the random layout's
    Random rng(deriveSeed(settings_.seed, 0x7a3ULL, swarm_index));
    p.yaws.resize(static_cast<std::size_t>(count));
    for (double& yaw : p.yaws) yaw = rng.uniform(-M_PI, M_PI);
  }
  checkUnknown(d, {"driver", "sensor", "ghost"});
  if (count > 1 && p.name.find("{i}") == std::string::npos)
    error(d.where(), "<swarm>: the name pattern '" + p.name + "' needs {i} to give " + std::to_string(count) +
                         " artifacts different names");
  if (p.type.empty() || errorCount() != errors_before) return false;
  readOverrides(d, p);
  return errorCount() == errors_before && types_.at(p.type).ok;
}

bool SceneLoader::readObstacle(const Descriptor& d, PlacementModel& p) {
  const std::size_t errors_before = errorCount();
  p.name = require(d, "name");
  p.xyz = read<Vec3>(d, "xyz", Vec3::Zero());
  p.rpy = read<Vec3>(d, "rpy", Vec3::Zero());
  p.allow_overlap = read<bool>(d, "allow_overlap", false);
  p.color = readColor(d, p.color);
  for (const Descriptor& c : d.children()) {
    if (!kShapeElements.contains(c.name())) continue;
    ShapeModel shape;
    shape.shape = readShape(c, &shape.xyz, &shape.rpy);
    shape.where = c.where();
    p.shapes.push_back(std::move(shape));
  }
  checkUnknown(d, kShapeElements);
  if (p.shapes.empty()) error(d.where(), "<obstacle>: needs at least one shape (box, sphere, cylinder, capsule)");
  return !p.name.empty() && errorCount() == errors_before;
}

}  // namespace ssx::detail
