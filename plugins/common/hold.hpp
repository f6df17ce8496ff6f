#pragma once
// hold="ARTIFACT": a driver's robot takes hold of another artifact (its first physic root) at
// `hold_time`, by a fixed joint as the two are or a ball joint at `hold_node`'s origin
// (PhysicNode::attach): a gripper or a hook closing. Shared by the drivers that carry things
// (quadrotor, diff_drive). It keeps no state: the hold is taken by the run whose period holds
// `hold_time`, and the joint is part of the saved state.
#include <ssx/artifact.hpp>
#include <ssx/descriptor.hpp>
#include <ssx/environment.hpp>
#include <ssx/parameters.hpp>
#include <ssx/physic_node.hpp>
#include <ssx/plugin.hpp>

#include <string>

namespace ssx::plugins {

inline constexpr ssx_plugin_param kHoldParameters[] = {
    param::text("hold", "", "an artifact it takes hold of at hold_time (its first physic root): a gripper or hook closing"),
    param::real("hold_time", "0", "s", param::nonNegative(), "hold: when it takes hold"),
    param::choice("hold_joint", "fixed", "fixed ball",
                  "hold: by a fixed joint as the two are, or a ball joint at hold_node's origin (free to turn about it)"),
    param::text("hold_node", "", "hold: the node that holds (default: the first root)"),
};

class Hold {
 public:
  // what it will hold; ConfigError at `hold` when no other artifact with a physic root has that
  // name, or it is a ghost (a real robot: nothing holds it)
  void configure(const Descriptor& params, Artifact& self) {
    const std::string name = params.get<std::string>("hold", "");
    if (name.empty()) {
      for (const char* key : {"hold_time", "hold_joint", "hold_node"})
        if (params.has(key)) throw params.errorAt(key, std::string(key) + " is for hold=\"ARTIFACT\", which is not given");
      return;
    }
    target_ = self.environment().findArtifact(name);
    if (target_ == nullptr || target_->rootCount() == 0 || target_ == &self)
      throw params.errorAt("hold", "no other artifact with a physic root is named '" + name + "'");
    if (self.environment().isGhost(*target_))
      throw params.errorAt("hold", "'" + name + "' is a ghost (a real robot): it cannot be held");
    hand_ = &self.nodeFromParameter(params, "hold_node");
    time_ = toNanoseconds(params.get<double>("hold_time"));
    ball_ = params.get<std::string>("hold_joint") == "ball";
  }
  // from the driver's step: the run whose period [time - period, time) holds hold_time takes hold
  void step(const StepInfo& info) const {
    if (target_ == nullptr || info.time - info.period > time_ || time_ >= info.time) return;
    hand_->attach(target_->root(), ball_ ? JointSpec::Kind::Ball : JointSpec::Kind::Fixed);
  }

 private:
  const Artifact* target_ = nullptr;
  PhysicNode* hand_ = nullptr;
  Nanoseconds time_ = 0;
  bool ball_ = false;
};

}  // namespace ssx::plugins
