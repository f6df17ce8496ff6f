// What happened to the robots of a run (ssx/flight_summary.hpp).
#include <ssx/environment.hpp>
#include <ssx/flight_summary.hpp>
#include <ssx/odometry.hpp>
#include <ssx/spatial_index.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ssx {

namespace {

// the farthest point of a node tree's shapes from the root's origin
double reach(const PhysicNodeSpec& node, const Pose& pose) {
  double r = 0;
  for (const Shape& s : node.shapes) {
    double own = 0;
    switch (s.kind) {
      case Shape::Kind::Box: own = 0.5 * s.size.norm(); break;
      case Shape::Kind::Sphere: own = s.radius; break;
      case Shape::Kind::Cylinder: own = std::hypot(s.radius, 0.5 * s.length); break;
      case Shape::Kind::Capsule: own = 0.5 * s.length + s.radius; break;
      case Shape::Kind::Mesh: own = s.mesh->min.cwiseAbs().cwiseMax(s.mesh->max.cwiseAbs()).norm(); break;
      case Shape::Kind::Plane: continue;
    }
    r = std::max(r, (pose * s.pose).position.norm() + own);
  }
  for (const PhysicNodeSpec& c : node.children) r = std::max(r, reach(c, pose * c.pose));
  return r;
}

// the farthest point of a node tree's shapes from the root's vertical axis (a ground robot's
// footprint): a shape's own horizontal extent is its bounding sphere's unless it is a cylinder or
// capsule standing upright, whose extent is its radius
double footprint(const PhysicNodeSpec& node, const Pose& pose) {
  double r = 0;
  for (const Shape& s : node.shapes) {
    const Pose at = pose * s.pose;
    const bool upright = std::abs((at.orientation * Vec3::UnitZ()).z()) > 1 - 1e-9;
    double own = 0;
    switch (s.kind) {
      case Shape::Kind::Box: own = 0.5 * s.size.norm(); break;
      case Shape::Kind::Sphere: own = s.radius; break;
      case Shape::Kind::Cylinder: own = upright ? s.radius : std::hypot(s.radius, 0.5 * s.length); break;
      case Shape::Kind::Capsule: own = upright ? s.radius : 0.5 * s.length + s.radius; break;
      case Shape::Kind::Mesh: own = s.mesh->min.cwiseAbs().cwiseMax(s.mesh->max.cwiseAbs()).norm(); break;
      case Shape::Kind::Plane: continue;
    }
    r = std::max(r, at.position.head<2>().norm() + own);
  }
  for (const PhysicNodeSpec& c : node.children) r = std::max(r, footprint(c, pose * c.pose));
  return r;
}

constexpr double kCrashedTilt = 0.5;  // cos 60 degrees: the body's up axis at most this far up
constexpr double kSearch = 5.0;       // m: closest approaches are looked for within this
constexpr double kRestingSpeed = 0.1;  // m/s: at rest on the ground, or moving with what it rests on

}  // namespace

void FlightRecorder::start(const Environment& env) {
  started_ = true;
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    const Artifact& a = env.artifact(i);
    if (a.rootCount() == 0) continue;
    const PhysicNode& root = a.root();
    if (root.isStatic()) {
      // the ground: a static artifact made of a plane
      const auto& shapes = root.spec().shapes;
      if (!shapes.empty() && shapes.front().kind == Shape::Kind::Plane) {
        ground_z_ = has_ground_ ? std::max(ground_z_, root.pose().position.z()) : root.pose().position.z();
        has_ground_ = true;
      }
      continue;
    }
    Robot r{i, reach(root.spec(), Pose{}), footprint(root.spec(), Pose{}), root.pose().position,
            root.state().linear_velocity};
    r.wheeled = dynamic_cast<const OdometryInterface*>(a.driver()) != nullptr;
    summary_.wheeled += r.wheeled ? 1 : 0;
    robots_.push_back(r);
  }
  summary_.robots = static_cast<std::int64_t>(robots_.size());
  last_time_ = toSeconds(env.time());
}

void FlightRecorder::observe(const Environment& env) {
  if (!started_) start(env);
  ++summary_.samples;
  const double now = toSeconds(env.time());
  const double explained = kManoeuvre * std::max(now - last_time_, 0.0);
  last_time_ = now;
  std::vector<Vec3> points;
  std::vector<std::size_t> ids;
  double largest = 0;
  for (std::size_t k = 0; k < robots_.size(); ++k) {
    Robot& r = robots_[k];
    const BodyState s = env.artifact(r.artifact).root().state();
    const Vec3& p = s.pose.position;
    r.flown += (p - r.last).norm();
    r.last = p;
    // an impact: a change of velocity no thrust explains
    const double change = (s.linear_velocity - r.last_velocity).norm() - explained;
    r.last_velocity = s.linear_velocity;
    const bool hitting = change > kImpactSpeed;
    if (hitting && !r.hitting) ++summary_.impacts;
    r.hitting = hitting;
    r.hit = r.hit || hitting;
    if (change > summary_.hardest_impact_mps && hitting) {
      summary_.hardest_impact_mps = change;
      summary_.hardest_impact_robot = env.artifact(r.artifact).name();
    }
    points.push_back(p);
    ids.push_back(k);
    largest = std::max(largest, r.radius);
  }
  // pairs near each other: the closest approach, and touches (a pair that was not touching at the last
  // sample). A pair closer than the closest so far is within that distance: after the first sample
  // the search shrinks to it (or to what a touch needs)
  const double closest = summary_.closest_approach_m;
  const double search = std::max(closest >= 0 ? std::min(kSearch, closest) : kSearch, 2 * largest);
  SpatialIndex index(search);
  index.rebuild(points, ids);
  std::vector<std::pair<std::size_t, std::size_t>> touching;
  std::vector<char> resting(robots_.size(), 0);  // on another robot: touching it, above it, moving with it
  std::vector<SpatialIndex::Hit> hits;
  const double t = toSeconds(env.time());
  for (std::size_t k = 0; k < robots_.size(); ++k) {
    hits.clear();
    index.query(points[k], search, hits);
    for (const auto& h : hits) {
      if (h.id <= k) continue;  // each pair once
      const double d = (points[k] - h.point).norm();
      const auto pair = [&] {
        return env.artifact(robots_[k].artifact).name() + " and " + env.artifact(robots_[h.id].artifact).name();
      };
      if (summary_.closest_approach_m < 0 || d < summary_.closest_approach_m) {
        summary_.closest_approach_m = d;
        summary_.closest_pair = pair();
      }
      // two ground robots touch side by side: their centres' horizontal distance against their
      // footprints (their bounding spheres reach far above and below what can touch)
      const bool ground = robots_[k].wheeled && robots_[h.id].wheeled;
      const bool touch = ground ? (points[k] - h.point).head<2>().norm() < robots_[k].footprint + robots_[h.id].footprint
                                : d < robots_[k].radius + robots_[h.id].radius;
      if (touch) {
        const std::size_t upper = points[k].z() > h.point.z() ? k : h.id, lower = upper == k ? h.id : k;
        if ((robots_[upper].last_velocity - robots_[lower].last_velocity).norm() < kRestingSpeed) resting[upper] = 1;
        touching.emplace_back(k, h.id);
        if (std::find(touching_.begin(), touching_.end(), touching.back()) == touching_.end()) {
          ++summary_.collisions;
          if (summary_.first_collision_s < 0) {
            summary_.first_collision_s = t;
            summary_.first_collision_pair = pair();
          }
        }
      }
    }
  }
  touching_ = std::move(touching);
  // the end states, as of now
  summary_.airborne = summary_.landed = summary_.on_wheels = summary_.crashed = 0;
  summary_.crashed_names.clear();
  for (std::size_t k = 0; k < robots_.size(); ++k) {
    const Robot& r = robots_[k];
    const Artifact& a = env.artifact(r.artifact);
    const BodyState s = a.root().state();
    const double up = (s.pose.orientation * Vec3::UnitZ()).z();
    const bool down = has_ground_ && s.pose.position.z() - ground_z_ < r.radius + 0.05;
    if (up < kCrashedTilt || (down && r.hit && !r.wheeled)) {
      ++summary_.crashed;
      if (summary_.crashed_names.size() < 10) summary_.crashed_names.push_back(a.name());
    } else if (r.wheeled) {
      ++summary_.on_wheels;
    } else if ((down && s.linear_velocity.norm() < kRestingSpeed) || resting[k]) {
      ++summary_.landed;
    } else {
      ++summary_.airborne;
    }
  }
}

FlightSummary FlightRecorder::summary() const {
  FlightSummary out = summary_;
  double flown = 0;
  for (const Robot& r : robots_) flown += r.flown;
  out.mean_distance_flown_m = robots_.empty() ? 0 : flown / static_cast<double>(robots_.size());
  return out;
}

std::string FlightSummary::str() const {
  char text[160];
  std::snprintf(text, sizeof text, "robots %lld: airborne %lld, landed %lld", static_cast<long long>(robots),
                static_cast<long long>(airborne), static_cast<long long>(landed));
  std::string out = text;
  if (on_wheels > 0) out += ", on wheels " + std::to_string(on_wheels);
  out += ", crashed " + std::to_string(crashed);
  if (!crashed_names.empty()) {
    out += " (";
    for (std::size_t i = 0; i < crashed_names.size(); ++i) out += (i ? ", " : "") + crashed_names[i];
    out += crashed > static_cast<std::int64_t>(crashed_names.size()) ? ", ...)" : ")";
  }
  std::snprintf(text, sizeof text, "; collisions %lld", static_cast<long long>(collisions));
  out += text;
  if (collisions > 0) {
    std::snprintf(text, sizeof text, ", first at %.2f s (", first_collision_s);
    out += text + first_collision_pair + ")";
  }
  if (closest_approach_m >= 0) {
    std::snprintf(text, sizeof text, "; closest approach %.2f m (", closest_approach_m);
    out += text + closest_pair + ")";
  }
  if (impacts > 0) {
    std::snprintf(text, sizeof text, "; impacts %lld, hardest %.1f m/s (", static_cast<long long>(impacts),
                  hardest_impact_mps);
    out += text + hardest_impact_robot + ")";
  }
  std::snprintf(text, sizeof text, "; mean distance %s %.2f m",
                wheeled == 0 ? "flown" : wheeled == robots ? "driven" : "travelled", mean_distance_flown_m);
  return out + text;
}

}  // namespace ssx
