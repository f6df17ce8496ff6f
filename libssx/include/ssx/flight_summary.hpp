#pragma once
/// @file
/// What happened to the robots of a run, beside how fast it ran: how many are flying, landed or
/// crashed at the end, which robots touched each other and when first, how close any two came, how
/// far they travelled. An observer fed between steps (`ssx run` feeds it every 10th step and prints
/// it after the timing summary; Python's `Environment.flight_summary()`).

#include <ssx/export.hpp>
#include <ssx/types.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace ssx {

class Environment;

/// The end state of one robot.
enum class RobotState : std::uint8_t {
  Airborne,  ///< above the ground, upright
  /// upright and at rest on the ground (within 5 cm of touching it), or resting on another robot:
  /// touching it, above its centre, moving with it (within 0.1 m/s)
  Landed,
  /// tilted more than 60 degrees from upright, or on the ground after an impact: a change of
  /// velocity between two observations larger, by more than kImpactSpeed, than 4 g could make
  Crashed,
};

/// The summary of a run's robots (FlightRecorder::summary).
struct SSX_EXPORT FlightSummary {
  std::int64_t robots = 0;    ///< artifacts with a dynamic physic root
  std::int64_t airborne = 0;  ///< of those, flying at the last observation
  std::int64_t landed = 0;    ///< at rest on the ground, or on another robot (RobotState::Landed)
  /// wheeled robots (their driver implements OdometryInterface) that are upright: neither flying
  /// nor landed, whatever their height (printed only when there are any)
  std::int64_t on_wheels = 0;
  std::int64_t crashed = 0;   ///< tilted over, or down after an impact (a wheeled robot: tilted over)
  std::vector<std::string> crashed_names;  ///< the first ten that crashed, by name
  /// Impacts: a robot's velocity changed between two observations by more than kImpactSpeed
  /// beyond what 4 g could do (a hit on the ground, an obstacle or another robot), counted once
  /// per hit.
  std::int64_t impacts = 0;
  double hardest_impact_mps = 0;     ///< the largest such change, m/s (0: none)
  std::string hardest_impact_robot;  ///< whose it was
  /// Robots touching: two robots closer than the sum of their radii (the farthest point of each one's
  /// shapes from its centre; for two wheeled robots, side by side on the ground, the horizontal
  /// distance against their footprints' radii), counted once per pair and touch.
  std::int64_t collisions = 0;
  double first_collision_s = -1;          ///< simulated time of the first, or -1
  std::string first_collision_pair;       ///< "a and b"
  double closest_approach_m = -1;         ///< between two robots' centres, over the samples; -1: fewer than two
  std::string closest_pair;               ///< "a and b"
  double mean_distance_flown_m = 0;       ///< path length per robot (flown or driven), from sample to sample
  std::int64_t wheeled = 0;               ///< robots on wheels (their drivers have odometry)
  std::int64_t samples = 0;               ///< observations the summary is made of
  /// "robots 25: airborne 24, landed 0, crashed 1 (q7); collisions 1, first at 3.20 s (q7 and q8);
  /// closest approach 0.18 m (q7 and q8); mean distance flown 4.20 m"; with wheeled robots
  /// "robots 17: airborne 1, landed 0, on wheels 16, crashed 0; ...; mean distance travelled 1.20 m"
  /// ("driven" when every robot is on wheels)
  std::string str() const;
};

/// Collects a FlightSummary over a run. A robot is an artifact with a dynamic physic root.
class SSX_EXPORT FlightRecorder {
 public:
  /// A change of velocity between two observations beyond what 4 g explain that counts as an
  /// impact, m/s: a free fall from 5 cm. A robot that lands at walking pace has none.
  static constexpr double kImpactSpeed = 1.0;
  /// The acceleration a robot's own thrust and gravity are granted between observations, m/s^2.
  static constexpr double kManoeuvre = 4 * 9.81;

  /// Looks at the robots of `env` as they are now (call between steps, from the stepping thread).
  void observe(const Environment& env);
  /// The summary so far; the end states are those of the last observation.
  FlightSummary summary() const;

 private:
  struct Robot {
    std::size_t artifact = 0;
    double radius = 0;
    double footprint = 0;  // the farthest point of its shapes from its vertical axis (wheeled robots)
    Vec3 last = Vec3::Zero();
    Vec3 last_velocity = Vec3::Zero();
    double flown = 0;
    bool hit = false;       // had an impact
    bool hitting = false;   // in one at the last observation (counted once per hit)
    bool wheeled = false;   // its driver implements OdometryInterface
  };
  void start(const Environment& env);

  bool started_ = false;
  std::vector<Robot> robots_;
  std::vector<std::pair<std::size_t, std::size_t>> touching_;  // pairs (robot indices) in contact at the last sample
  FlightSummary summary_;
  double last_time_ = 0;
  double ground_z_ = 0;
  bool has_ground_ = false;
};

}  // namespace ssx
