#include "references.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace ssx::quadrotor {

namespace {

// room for the neighbours a formation robot senses at once, reserved at start
constexpr std::size_t kTypicalNeighbours = 16;

// the cells of one CSV line, trimmed
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) {
    const auto first = cell.find_first_not_of(" \t\r");
    const auto last = cell.find_last_not_of(" \t\r");
    out.push_back(first == std::string::npos ? std::string() : cell.substr(first, last - first + 1));
  }
  return out;
}

bool number(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(value);
}

}  // namespace

Trajectory Trajectory::read(const std::filesystem::path& file) {
  std::istringstream in;
  try {
    in.str(readInputFile(file));
  } catch (const ConfigError& e) {
    throw ConfigError(e.where(), "cannot read the trajectory file: " + e.detail());
  }
  Trajectory t;
  std::size_t columns = 0;
  int line_number = 0;
  bool first = true;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    const SourceLocation where{file.string(), line_number};
    const auto start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    const auto row = cells(line);
    std::vector<double> values(row.size());
    bool numeric = true;
    for (std::size_t i = 0; i < row.size(); ++i) numeric = numeric && number(row[i], values[i]);
    if (!numeric) {
      if (first) {  // a header
        first = false;
        continue;
      }
      throw ConfigError(where, "a trajectory row is t, x, y, z[, yaw]: finite numbers separated by commas");
    }
    first = false;
    if (row.size() != 4 && row.size() != 5)
      throw ConfigError(where, "a trajectory row is t, x, y, z[, yaw]: 4 or 5 numbers, got " +
                                   std::to_string(row.size()));
    if (columns != 0 && row.size() != columns)
      throw ConfigError(where, "every trajectory row has the same columns: " + std::to_string(columns) +
                                   " before, " + std::to_string(row.size()) + " here");
    columns = row.size();
    if (values[0] < 0) throw ConfigError(where, "trajectory times start at 0 or later (s after start_time)");
    if (!t.times.empty() && !(values[0] > t.times.back()))
      throw ConfigError(where, "trajectory times must increase from row to row");
    t.times.push_back(values[0]);
    t.positions.emplace_back(values[1], values[2], values[3]);
    if (columns == 5) t.yaws.push_back(values[4]);
  }
  if (t.times.empty()) throw ConfigError({file.string(), line_number}, "the trajectory file has no rows");
  return t;
}

std::size_t Trajectory::rowAt(double t) const {
  const auto after = std::upper_bound(times.begin(), times.end(), t);
  return after == times.begin() ? 0 : static_cast<std::size_t>(after - times.begin()) - 1;
}

ReferenceParams::ReferenceParams(const Descriptor& params) {
  reference = params.get<std::string>("reference");
  target = given<Vec3>(params, "target");
  center = given<Vec3>(params, "center");
  offset = params.get<Vec3>("offset");
  center_offset = params.get<Vec3>("center_offset");
  amplitude = params.get<double>("amplitude");
  eight_period = params.get<double>("eight_period");
  yaw_rate = params.get<double>("yaw_rate");
  start_time = params.get<double>("start_time");
  if (reference == "trajectory") {
    const auto* file = params.find("trajectory");
    if (file == nullptr || file->value.empty())
      throw params.errorAt("reference", "reference=\"trajectory\" needs trajectory=\"FILE.csv\" (rows t, x, y, z[, yaw])");
    std::filesystem::path path = file->value;
    if (path.is_relative() && !file->where.file.empty())
      path = std::filesystem::path(file->where.file).parent_path() / path;
    trajectory = std::make_shared<const Trajectory>(Trajectory::read(path));
  }
  follow = params.get<std::string>("follow", "");
  if (reference == "follow" && follow.empty())
    throw params.errorAt("reference", "reference=\"follow\" needs follow=\"ARTIFACT\" (the robot to follow)");
  follow_offset = params.get<Vec3>("follow_offset");
  follow_height = params.get<double>("follow_height");
  land_time = params.get<double>("land_time");
  descent_speed = params.get<double>("descent_speed");
  follow_lead = params.get<double>("follow_lead");
  formation_size = static_cast<std::size_t>(params.get<std::int64_t>("formation_size"));
  formation_radius = params.get<double>("formation_radius");
  formation_center = params.get<Vec3>("formation_center");
  formation_gain = params.get<double>("formation_gain");
  formation_max_speed = params.get<double>("formation_max_speed");
  formation_anchor_gain = params.get<double>("formation_anchor_gain");
  obstacle_distance = params.get<double>("obstacle_distance");
  obstacle_saturation = params.get<double>("obstacle_saturation");
}

void References::configure(const ReferenceParams& c, const Descriptor& params, const Artifact& a,
                           const RangeMeasurement* range) {
  artifact_ = &a;
  const Vec3 start = a.placement().position;
  hover_.position = c.target.value_or(Vec3(start + c.offset));
  // an external reference starts at the placed heading, which it holds until a set-point says otherwise
  const Vec3 placed_forward = a.placement().orientation * Vec3::UnitX();
  hover_.yaw = std::atan2(placed_forward.y(), placed_forward.x());
  eight_.center = c.center.value_or(Vec3(start + c.center_offset));
  eight_.amplitude = c.amplitude;
  eight_.period = c.eight_period;
  eight_.yaw_rate = c.yaw_rate;
  start_time_ = c.start_time;
  trajectory_ = c.trajectory;
  if (c.reference == "hover") {
    source_ = Source::Hover;
  } else if (c.reference == "eight_horizontal" || c.reference == "eight_vertical") {
    source_ = Source::Eight;
    eight_.vertical = c.reference == "eight_vertical";
  } else if (c.reference == "trajectory") {
    source_ = Source::Trajectory;
  } else if (c.reference == "formation") {
    source_ = Source::Formation;
    formation_.size = c.formation_size;
    const auto index = params.get<std::int64_t>("formation_index");
    if (index < 0 || static_cast<std::size_t>(index) >= formation_.size || static_cast<std::size_t>(index) > a.index())
      throw params.error("formation_index must be in [0, formation_size) and the members one swarm");
    formation_index_ = static_cast<std::size_t>(index);
    formation_base_ = a.index() - formation_index_;
    formation_.radius = c.formation_radius;
    formation_.center = c.formation_center;
    formation_.gain = c.formation_gain;
    formation_.max_speed = c.formation_max_speed;
    formation_.anchor_gain = c.formation_anchor_gain;
    formation_.obstacle_distance = c.obstacle_distance;
    formation_.obstacle_saturation = c.obstacle_saturation;
    if (range == nullptr) throw params.error("reference=\"formation\" needs a range sensor on the artifact");
    // read in place: the sensor's measurement changes only when it senses, before the driver's step
    range_ = range;
    // room for the neighbours a robot usually has, so that flying allocates nothing; a robot
    // that meets more grows this once, to the most it has met
    desired_distance_.reserve(std::min(kTypicalNeighbours, formation_.size));
    virtual_point_ = start + c.offset;
    own_target_ = formation_.target(formation_index_);
  } else if (c.reference == "follow") {
    source_ = Source::Follow;
    followed_ = a.environment().findArtifact(c.follow);
    if (followed_ == nullptr || followed_->rootCount() == 0 || followed_ == &a)
      throw params.errorAt("follow", "no other artifact with a physic root is named '" + c.follow + "'");
    follow_offset_ = c.follow_offset;
    follow_height_ = c.follow_height;
    land_time_ = c.land_time;
    descent_speed_ = c.descent_speed;
    follow_lead_ = c.follow_lead;
  } else {
    source_ = Source::External;
    external_ = hover_;
  }
  configured_ = source_;
}

Setpoint References::at(double t, double dt) {
  switch (source_) {
    case Source::Hover:
      return hover_;
    case Source::External:
      return external_;
    case Source::Formation: {
      // the formation starts after start_time; until then the vehicle climbs to its start + offset
      if (t >= start_time_) formationStep(dt);
      Setpoint s;
      s.position = virtual_point_;
      s.velocity = virtual_velocity_;
      return s;
    }
    case Source::Eight: {
      // hold the curve's start until start_time, then fly it
      if (t < start_time_) {
        Setpoint s = eight_.at(0.0);
        s.velocity.setZero();
        s.acceleration.setZero();
        s.yaw_rate = 0;
        return s;
      }
      return eight_.at(t - start_time_);
    }
    case Source::Follow: {
      // above the point on the followed robot, moving with it; from land_time down onto it (and
      // 2 cm into it, so that it presses on the deck until its motors stop)
      const BodyState r = followed_->state();
      const Vec3 point = r.pose.transformPoint(follow_offset_);
      double height = follow_height_, sink = 0;
      if (land_time_ >= 0 && t >= land_time_) {
        height = std::max(-0.02, follow_height_ - descent_speed_ * (t - land_time_));
        if (height > -0.02) sink = descent_speed_;
      }
      const Vec3 moving = r.linear_velocity + r.angular_velocity.cross(point - r.pose.position);
      Setpoint s;
      s.position = point + follow_lead_ * moving + Vec3(0, 0, height);
      s.velocity = moving - Vec3(0, 0, sink);
      s.yaw = hover_.yaw;
      return s;
    }
    case Source::Trajectory: {
      const std::size_t row = trajectory_->rowAt(t - start_time_);
      Setpoint s;
      s.position = trajectory_->positions[row];
      s.yaw = trajectory_->yaws.empty() ? hover_.yaw : trajectory_->yaws[row];
      return s;
    }
  }
  return hover_;
}

bool References::touchedDown(const Vec3& position, double t) const {
  if (source_ != Source::Follow || land_time_ < 0 || t < land_time_) return false;
  const Vec3 d = position - followed_->state().pose.transformPoint(follow_offset_);
  return d.z() < 0.015 && d.head<2>().norm() < 0.03;
}

// d* to a member: computed the first time it is seen, then looked up (neighbours change slowly)
double References::desiredDistance(std::size_t member) {
  auto it = std::lower_bound(desired_distance_.begin(), desired_distance_.end(), member,
                             [](const auto& e, std::size_t m) { return e.first < m; });
  if (it != desired_distance_.end() && it->first == member) return it->second;
  const double d = (own_target_ - formation_.target(member)).norm();
  desired_distance_.insert(it, {member, d});
  return d;
}

double References::formationError() const {
  double sum = 0;
  std::size_t members = 0;
  for (const auto& d : seen()) {
    if (d.obstacle || d.artifact < formation_base_ || d.artifact >= formation_base_ + formation_.size) continue;
    // the pairs the shape is made of: neighbours on the target sphere within sensing range
    const double d_star = (own_target_ - formation_.target(d.artifact - formation_base_)).norm();
    if (d_star >= formation_.sensing_range) continue;
    sum += std::abs(d.relative.norm() - d_star);
    ++members;
  }
  return members > 0 ? sum / static_cast<double>(members) : std::numeric_limits<double>::quiet_NaN();
}

// the formation's virtual point: v = gain sum_j g(d_ij, d*_ij) u_ij + repulsion from whatever is too
// close + a pull towards the own target, then no approach towards anything inside its safety
// distance, saturated at a speed that drops in a crowd; integrated at the position loop's rate
void References::formationStep(double dt) {
  const Formation& f = formation_;
  Vec3 v = Vec3::Zero();
  const Vec3& own_target = own_target_;
  for (const auto& d : seen()) {
    if (d.distance <= 1e-9) continue;
    const Vec3 away = -d.relative / d.relative.norm();  // u_ij, from the neighbour to this robot
    if (d.obstacle) {
      v += 2.0 * f.max_speed * f.obstacleGradient(d.distance) * away;
      continue;
    }
    // every robot close by is kept clear of; members are also held at their desired distance
    v += f.max_speed * f.clearanceGradient(d.relative.norm()) * away;
    if (d.artifact < formation_base_ || d.artifact >= formation_base_ + f.size) continue;
    const double d_star = desiredDistance(d.artifact - formation_base_);
    v += f.gain * f.pairGradient(d.relative.norm(), d_star) * away;
  }
  // v_cmd: each member knows its own place on the sphere, capped at half the top speed
  const BodyState s = artifact_->state();
  Vec3 anchor = f.anchor_gain * (own_target - s.pose.position);
  if (anchor.norm() > 0.5 * f.max_speed) anchor *= 0.5 * f.max_speed / anchor.norm();
  v += anchor;
  // never approach an obstacle or robot inside its safety distance (fully inside the saturation
  // distance, partly on the way there)
  for (const auto& d : seen()) {
    const double dist = d.relative.norm();
    if (dist <= 1e-9) continue;
    const double outer = d.obstacle ? f.obstacle_distance : f.clearance;
    const double inner = d.obstacle ? f.obstacle_saturation : 0.9 * f.clearance;
    if (dist >= outer) continue;
    const Vec3 toward = d.relative / dist;
    const double approach = v.dot(toward);
    if (approach <= 0) continue;
    const double weight = std::clamp((outer - dist) / (outer - inner), 0.0, 1.0);
    v -= weight * approach * toward;
  }
  // slower in a crowd: full speed with nobody within 2 m, a crawl at 0.7 m
  double nearest = 1e9;
  for (const auto& d : seen())
    if (!d.obstacle) nearest = std::min(nearest, d.relative.norm());
  const double speed = f.max_speed * std::clamp((nearest - 0.7) / 1.3, 0.15, 1.0);
  if (v.norm() > speed) v *= speed / v.norm();
  // the virtual point stays close to the vehicle (a short leash: the velocity feed-forward does the
  // driving, so a stop in v is a stop of the vehicle)
  virtual_velocity_ = v;
  virtual_point_ = s.pose.position + (virtual_point_ - s.pose.position).cwiseMin(0.15).cwiseMax(-0.15) + v * dt;
}

void References::saveState(StateWriter& out) const {
  out.write(source_);
  saveSetpoint(out, external_);
  out.write(virtual_point_);
  out.write(virtual_velocity_);
}

void References::loadState(StateReader& in) {
  Source source = Source::Hover;
  in.read(source);
  // (a scene's reference changes only to external set-points while it runs)
  if (source != configured_ && source != Source::External)
    throw StateError("quadrotor: the saved reference source does not fit this driver (corrupted, or another scene)");
  source_ = source;
  loadSetpoint(in, external_);
  in.read(virtual_point_);
  in.read(virtual_velocity_);
}

}  // namespace ssx::quadrotor
