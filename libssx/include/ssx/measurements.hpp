#pragma once
/// @file
/// Measurement types shared between plugins: a sensor in one library and a driver in another
/// agree on these, and callbacks receive them without copies.

#include <ssx/export.hpp>
#include <ssx/plugin.hpp>
#include <ssx/types.hpp>

#include <cstdint>

namespace ssx {

/// Simulated time, as a clock sensor reports it.
struct SSX_EXPORT ClockMeasurement : Measurement {
  std::int64_t step = 0;
  double seconds = 0.0;
  ~ClockMeasurement() override;
};

/// Pose and twist of a node, world frame, possibly with noise.
struct SSX_EXPORT PoseMeasurement : Measurement {
  Pose pose;
  Vec3 linear_velocity = Vec3::Zero();   ///< m/s, world frame
  Vec3 angular_velocity = Vec3::Zero();  ///< rad/s, world frame
  ~PoseMeasurement() override;
};

}  // namespace ssx
