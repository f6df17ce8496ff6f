#pragma once
// Where a rotorcraft's position-level set-point comes from: hover at a point, the fidelity study's
// figure eights, the sphere formation (range sensing), a trajectory file, another robot to follow
// and land on, or external commands (Python, a bridge, a program). Parameters: kReferenceParameters.
#include "quadrotor_model.hpp"

#include <ssx/ssx.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace ssx::quadrotor {

inline constexpr ssx_plugin_param kReferenceParameters[] = {
    param::choice("reference", "hover", "hover eight_horizontal eight_vertical external formation trajectory follow",
                  "where the set-point comes from"),
    param::vec3("target", "", "m", param::any(), "hover point (default: the start plus offset)"),
    param::vec3("offset", "0 0 0", "m", param::any(), "hover point, or the formation's start, relative to the start"),
    param::vec3("center", "", "m", param::any(), "figure eight centre (default: the start plus center_offset)"),
    param::vec3("center_offset", "0 0 0", "m", param::any(), "figure eight centre relative to the start"),
    param::real("amplitude", "1", "m", param::positive(), "figure eight amplitude A"),
    param::real("eight_period", "12", "s", param::positive(), "figure eight period T"),
    param::real("yaw_rate", "0.2", "rad/s", param::any(), "figure eight yaw rate"),
    param::real("start_time", "0", "s", param::any(),
                "figure eight, formation or trajectory start; before it the vehicle holds"),
    param::text("trajectory", "",
                "reference=\"trajectory\": a CSV file (relative to the file that names it) of rows t, x, y, z[, yaw] "
                "in s, m and rad, t increasing from 0 after start_time; each row is held until the next (zero-order "
                "hold), the last one for good"),
    param::integer("formation_index", "0", param::nonNegative(), "this member's index in the formation"),
    param::integer("formation_size", "70", param::between(1, 10'000'000), "members in the formation"),
    param::real("formation_radius", "4", "m", param::positive(), "sphere radius"),
    param::vec3("formation_center", "0 0 5", "m", param::any(), "sphere centre"),
    param::real("formation_gain", "0.2", "m/s", param::positive(), "gain of the shape potentials"),
    param::real("formation_max_speed", "1", "m/s", param::positive(), "top speed of the virtual point"),
    param::real("formation_anchor_gain", "0.5", "1/s", param::nonNegative(), "pull towards the own target"),
    param::real("obstacle_distance", "0.5", "m", param::positive(), "obstacles repel inside it"),
    param::real("obstacle_saturation", "0.2", "m", param::positive(), "the repulsion is saturated inside it"),
    param::text("follow", "", "reference=\"follow\": the artifact it follows (and lands on)"),
    param::vec3("follow_offset", "0 0 0", "m", param::any(),
                "follow: where its origin rests when landed, in the followed artifact's frame (on its deck)"),
    param::real("follow_height", "0.5", "m", param::nonNegative(), "follow: how far above that point it flies"),
    param::real("land_time", "-1", "s", param::any(),
                "follow: when it descends onto the point at descent_speed and, once there, stops its motors; "
                "negative: it never lands"),
    param::real("descent_speed", "0.2", "m/s", param::positive(), "follow: how fast it descends to land"),
    param::real("follow_lead", "0", "s", param::between(0, 10),
                "follow: the set-point leads the point by the robot's velocity times this (a position loop without "
                "feed-forward, as the crazyflie's PID, lags a moving point by speed / gain: 0.5 s at its gain of 2)"),
};

/// A trajectory file's rows: times (s, increasing) with positions and, if the file has a fifth
/// column, yaws.
struct Trajectory {
  std::vector<double> times;
  std::vector<Vec3> positions;
  std::vector<double> yaws;  ///< empty without a yaw column
  /// Reads `file`: rows `t, x, y, z[, yaw]` (every row the same number of columns), blank lines
  /// and lines starting with '#' skipped, a first line of words taken as a header. Throws
  /// ConfigError at the file's line for anything else.
  static Trajectory read(const std::filesystem::path& file);
  /// The row in force at t (zero-order hold: the last row at or before t; the first before it).
  std::size_t rowAt(double t) const;
};

/// The references' parameters, parsed (all but the member's own formation_index).
struct ReferenceParams {
  std::string reference;
  std::optional<Vec3> target, center;
  Vec3 offset, center_offset;
  double amplitude, eight_period, yaw_rate, start_time;
  std::shared_ptr<const Trajectory> trajectory;  ///< reference="trajectory"
  std::size_t formation_size;
  double formation_radius;
  Vec3 formation_center;
  double formation_gain, formation_max_speed, formation_anchor_gain, obstacle_distance, obstacle_saturation;
  std::string follow;  ///< reference="follow": the artifact followed
  Vec3 follow_offset;
  double follow_height, land_time, descent_speed, follow_lead;
  explicit ReferenceParams(const Descriptor& params);
};

class References {
 public:
  enum class Source { Hover, Eight, External, Formation, Trajectory, Follow };
  /// `range`: the range sensor's latest measurement (the formation needs one).
  void configure(const ReferenceParams& c, const Descriptor& params, const Artifact& a, const RangeMeasurement* range);
  Source source() const { return source_; }
  /// The set-point at simulated time t, dt after the previous call (the formation moves its
  /// virtual point by dt).
  Setpoint at(double t, double dt);
  /// External set-points and trajectories hold their yaw; the others give a yaw rate only.
  bool holdsHeading() const { return source_ == Source::External || source_ == Source::Trajectory; }
  /// Switches to an external set-point, held until the next.
  void setExternal(const Setpoint& setpoint) {
    external_ = setpoint;
    source_ = Source::External;
  }
  /// Following: whether a vehicle at `position` has come down on the followed robot's deck (t past
  /// land_time, within 1.5 cm above the landing point and 3 cm beside it): its motors may stop.
  bool touchedDown(const Vec3& position, double t) const;
  /// In formation: the mean | distance - desired distance | to the members it sees whose places
  /// on the sphere are within sensing range of its own (NaN: none).
  double formationError() const;

  void saveState(StateWriter& out) const;
  void loadState(StateReader& in);

 private:
  void formationStep(double dt);
  double desiredDistance(std::size_t member);
  std::span<const RangeMeasurement::Detection> seen() const {
    return range_ != nullptr ? std::span<const RangeMeasurement::Detection>(range_->detections)
                             : std::span<const RangeMeasurement::Detection>();
  }

  Source source_ = Source::Hover;
  Source configured_ = Source::Hover;  // the scene's
  const Artifact* artifact_ = nullptr;
  Setpoint hover_;
  double start_time_ = 0;
  Setpoint external_;
  FigureEight eight_;
  std::shared_ptr<const Trajectory> trajectory_;
  // following
  const Artifact* followed_ = nullptr;
  Vec3 follow_offset_ = Vec3::Zero();
  double follow_height_ = 0, land_time_ = -1, descent_speed_ = 0, follow_lead_ = 0;
  // the formation
  const RangeMeasurement* range_ = nullptr;  // the range sensor's latest measurement
  std::size_t formation_index_ = 0, formation_base_ = 0;
  Vec3 virtual_point_ = Vec3::Zero();
  Vec3 virtual_velocity_ = Vec3::Zero();
  Vec3 own_target_ = Vec3::Zero();
  std::vector<std::pair<std::size_t, double>> desired_distance_;  // member -> d*, sorted; filled as met
  Formation formation_;
};

}  // namespace ssx::quadrotor
