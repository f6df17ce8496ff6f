#pragma once
// Environment effects on a rotorcraft, each usable by any robot's driver: the air it flies through
// (mean wind, one gust, Dryden turbulence), ground effect on its rotors, downwash from robots above.
// Parameters: kWindParameters, kGroundEffectParameters, kDownwashParameters; the models themselves
// (DrydenTurbulence, groundEffectGain, downwashForce) are in quadrotor_model.hpp.
#include "quadrotor_model.hpp"

#include <ssx/ssx.hpp>

#include <vector>

namespace ssx::quadrotor {

/// The air a body flies through: mean wind, one 1-cosine gust, Dryden turbulence (MIL-F-8785C).
struct WindParams {
  Vec3 mean = Vec3::Zero();    ///< m/s, world frame
  Vec3 gust = Vec3::Zero();    ///< m/s, amplitude of the gust
  double gust_start = 0;       ///< s
  double gust_duration = 1;    ///< s, it rises and falls within it
  double turbulence_w20 = 0;   ///< m/s, wind speed at 20 ft the turbulence is scaled by (0: none)
  double min_airspeed = 1;     ///< m/s, the least airspeed its length scales are travelled at
  bool active() const { return !mean.isZero() || !gust.isZero() || turbulence_w20 > 0; }

  /// The scene's wind (`<wind>`), each of whose values the artifact's own parameters override
  /// where they are given.
  static WindParams of(const WindSettings& scene);
};

inline constexpr ssx_plugin_param kWindParameters[] = {
    param::vec3("wind", "", "m/s", param::any(), "mean wind, world frame (default: the scene's <wind>, else none)"),
    param::real("turbulence_w20", "", "m/s", param::nonNegative() & param::atMost(50),
                "Dryden turbulence (MIL-F-8785C): the wind speed at 20 ft it is scaled by (0: none; light 7.7, "
                "moderate 15.4; default: the scene's)"),
    param::real("turbulence_min_airspeed", "", "m/s", param::positive(),
                "the airspeed the turbulence's length scales are travelled at, at least (frozen turbulence; EST; "
                "default: the scene's, 1)"),
    param::vec3("gust", "", "m/s", param::any(), "amplitude of one 1-cosine gust, world frame (default: the scene's)"),
    param::real("gust_start", "", "s", param::nonNegative(), "when the gust begins (default: the scene's, 0)"),
    param::real("gust_duration", "", "s", param::positive(), "how long it lasts (rises and falls; default: the scene's, 1)"),
};

/// The scene's wind with the artifact's own wind parameters over it.
WindParams windParams(const Descriptor& params, const WindSettings& scene);

class Wind {
 public:
  /// `ground_z`: the ground plane the turbulence's height is measured from (-inf: none, then 0).
  void configure(const WindParams& params, double ground_z);
  bool active() const { return active_; }
  const WindParams& params() const { return p_; }
  /// Adds `offset` (m/s, world frame) to the configured mean wind from now on (zero: as configured).
  void setOffset(const Vec3& offset) {
    p_.mean = configured_mean_ + offset;
    active_ = p_.active();
  }
  /// The air's velocity (world frame) at a body at `position` moving at `velocity`, at time t; the
  /// turbulence advances by dt with draws from `random`.
  Vec3 air(double t, double dt, const Vec3& position, const Vec3& velocity, Random& random);
  void saveState(StateWriter& out) const { out.write(turbulence_.state()); }
  void loadState(StateReader& in) { turbulence_.setState(in.get<std::array<double, 5>>()); }

 private:
  WindParams p_;
  Vec3 configured_mean_ = Vec3::Zero();
  double ground_z_ = 0;
  bool active_ = false;
  DrydenTurbulence turbulence_;
};

inline constexpr ssx_plugin_param kGroundEffectParameters[] = {
    param::flag("ground_effect", "false", "thrust gain near the ground (Cheeseman-Bennett), per rotor"),
};

/// The height of the highest horizontal ground plane among the environment's static shapes
/// (-inf: none).
double groundHeight(const Environment& env);

inline constexpr ssx_plugin_param kDownwashParameters[] = {
    param::flag("downwash", "false", "robots above push this one down (gym-pybullet-drones' model)"),
    param::real("downwash_c1", "2267.18", "N", param::positive(), "model coefficient (fitted on Crazyflies)"),
    param::real("downwash_c2", "0.16", "", param::any(), "model coefficient (fitted on Crazyflies)"),
    param::real("downwash_c3", "-0.11", "m", param::any(), "model coefficient (fitted on Crazyflies)"),
    param::real("downwash_range", "3", "m", param::positive(), "robots farther than this are not looked at"),
    param::real("downwash_min_height", "0.1", "m", param::nonNegative(),
                "robots less than this above count as beside, not above (the fitted form diverges; EST)"),
};

struct DownwashParams {
  double c1 = 2267.18, c2 = 0.16, c3 = -0.11;  ///< downwashForce's coefficients
  double range = 3;                            ///< m
  double min_dz = 0.1;                         ///< m
  static DownwashParams of(const Descriptor& params);
};

/// Downwash on a robot from the rotorcraft above it (artifacts whose driver takes rotor commands:
/// ssx::CommandInterface with rotorCount() > 0). Needs neighbour queries of at least `range`.
class Downwash {
 public:
  explicit Downwash(const DownwashParams& p = {}) : p_(p) {}
  const DownwashParams& params() const { return p_; }
  /// The vertical force (N, world z, negative: down) on artifact `self` at `here` with rotors of
  /// `rotor_radius`.
  double push(const Environment& env, std::size_t self, const Vec3& here, double rotor_radius);

 private:
  DownwashParams p_;
  std::vector<SpatialIndex::Hit> above_;  // neighbours, reused
};

}  // namespace ssx::quadrotor
