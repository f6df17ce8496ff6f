#pragma once
// Whether a body state or a command is finite: the guards of the snapshot and drivers phases.

#include <ssx/physic_engine.hpp>

namespace ssx::detail {

inline bool finite(const BodyState& s) {
  return s.pose.position.allFinite() && s.pose.orientation.coeffs().allFinite() && s.linear_velocity.allFinite() &&
         s.angular_velocity.allFinite();
}

inline bool finite(const Wrench& w) { return w.force.allFinite() && w.torque.allFinite(); }

}  // namespace ssx::detail
