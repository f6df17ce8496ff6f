#pragma once
// A ground robot's behaviour, behind one interface: each run it reads what the robot senses (the
// artifact's sensors, its odometry) and sets the wheels' speeds (DriveModel::setWheels or
// setTwist). The diff_drive driver holds at most one, chosen at load (`controller`); a command
// from outside takes over from it. The built-in ones are in behaviours.hpp; a plugin of one's own
// derives a driver from ssx::ground::DiffDrive (diff_drive.hpp) and returns its controller from
// makeController (docs/ground-robots.md shows one).
#include "drive_model.hpp"

#include <ssx/ssx.hpp>

namespace ssx::ground {

/// What a controller reads and drives in one run.
struct GroundInputs {
  Artifact& artifact;        ///< the robot: its sensors' latest measurements
  const Environment& environment;  ///< the others (what it takes hold of)
  DriveModel& drive;         ///< its wheels: set their speeds here
  const Odometry& odometry;  ///< as of the previous run
  Random& random;            ///< the driver's stream (draws are part of the run's bits)
};

class GroundController {
 public:
  virtual ~GroundController() = default;
  /// One run of the driver at simulated time `t` (s).
  virtual void step(double t, GroundInputs& in) = 0;
  virtual void saveState(StateWriter& /*out*/) const {}
  virtual void loadState(StateReader& /*in*/) {}
};

/// The index of the artifact's first sensor producing M, or -1.
template <class M>
int sensorOf(const Artifact& a) {
  for (std::size_t i = 0; i < a.sensorCount(); ++i)
    if (dynamic_cast<const M*>(&a.sensor(i).latest()) != nullptr) return static_cast<int>(i);
  return -1;
}

/// The latest measurement of sensor `index` (found by sensorOf<M>).
template <class M>
const M& latestOf(const Artifact& a, int index) {
  return static_cast<const M&>(a.sensor(static_cast<std::size_t>(index)).latest());
}

}  // namespace ssx::ground
