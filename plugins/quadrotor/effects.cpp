#include "effects.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace ssx::quadrotor {

WindParams WindParams::of(const WindSettings& s) {
  WindParams p;
  p.mean = s.mean;
  p.gust = s.gust;
  p.gust_start = s.gust_start;
  p.gust_duration = s.gust_duration;
  p.turbulence_w20 = s.turbulence_w20;
  p.min_airspeed = s.turbulence_min_airspeed;
  return p;
}

WindParams windParams(const Descriptor& params, const WindSettings& scene) {
  WindParams p = WindParams::of(scene);
  p.mean = params.get<Vec3>("wind", p.mean);
  p.gust = params.get<Vec3>("gust", p.gust);
  p.gust_start = params.get<double>("gust_start", p.gust_start);
  p.gust_duration = params.get<double>("gust_duration", p.gust_duration);
  p.turbulence_w20 = params.get<double>("turbulence_w20", p.turbulence_w20);
  p.min_airspeed = params.get<double>("turbulence_min_airspeed", p.min_airspeed);
  return p;
}

void Wind::configure(const WindParams& params, double ground_z) {
  p_ = params;
  configured_mean_ = params.mean;
  ground_z_ = ground_z;
  active_ = p_.active();
}

Vec3 Wind::air(double t, double dt, const Vec3& position, const Vec3& velocity, Random& random) {
  Vec3 air = p_.mean;
  const double tg = t - p_.gust_start;
  if (tg >= 0 && tg <= p_.gust_duration)
    air += 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * tg / p_.gust_duration)) * p_.gust;
  if (p_.turbulence_w20 > 0) {
    const double height = position.z() - (std::isfinite(ground_z_) ? ground_z_ : 0.0);
    const auto scales = DrydenTurbulence::scales(height, p_.turbulence_w20);
    const double airspeed = std::max((velocity - p_.mean).norm(), p_.min_airspeed);
    const Vec3 uvw = turbulence_.step(dt, scales, airspeed, random);
    // u along the mean wind's horizontal direction (x without one), w up
    const Vec3 flat(p_.mean.x(), p_.mean.y(), 0);
    const Vec3 along = flat.norm() > 1e-9 ? Vec3(flat.normalized()) : Vec3(Vec3::UnitX());
    air += uvw.x() * along + uvw.y() * Vec3::UnitZ().cross(along) + uvw.z() * Vec3::UnitZ();
  }
  return air;
}

double groundHeight(const Environment& env) {
  double z = -std::numeric_limits<double>::infinity();
  for (const auto& shape : env.staticShapes()) {
    if (shape.shape.kind != Shape::Kind::Plane) continue;
    const Pose world = shape.world * shape.shape.pose;
    if ((world.orientation * Vec3::UnitZ()).z() > 1.0 - 1e-9) z = std::max(z, world.position.z());
  }
  return z;
}

DownwashParams DownwashParams::of(const Descriptor& params) {
  DownwashParams p;
  p.c1 = params.get<double>("downwash_c1");
  p.c2 = params.get<double>("downwash_c2");
  p.c3 = params.get<double>("downwash_c3");
  p.range = params.get<double>("downwash_range");
  p.min_dz = params.get<double>("downwash_min_height");
  return p;
}

double Downwash::push(const Environment& env, std::size_t self, const Vec3& here, double rotor_radius) {
  above_.clear();  // neighbors() appends
  env.neighbors(here, p_.range, above_);
  double push = 0;
  for (const auto& hit : above_) {
    if (hit.id == self) continue;
    // rotorcraft only (what another artifact's driver is, not its state)
    const auto* rotorcraft = dynamic_cast<const CommandInterface*>(env.artifact(hit.id).driver());
    if (rotorcraft == nullptr || rotorcraft->rotorCount() == 0) continue;
    const Vec3 d = hit.point - here;
    push += downwashForce(d.z(), d.head<2>().norm(), rotor_radius, p_.c1, p_.c2, p_.c3, p_.min_dz);
  }
  return push;
}

}  // namespace ssx::quadrotor
