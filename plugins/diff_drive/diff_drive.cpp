#include "diff_drive.hpp"

#include <cmath>
#include <stdexcept>

namespace ssx::ground {

void DiffDrive::validate(const Descriptor& params, const PluginContext& context) {
  DriveModel::validate(params, *context.artifact);
  validateBehaviour(params, *context.artifact);
}

void DiffDrive::configure(const Descriptor& params, PluginSetup&) {
  hold_.configure(params, artifact());
  drive_.configure(params, artifact());
  controller_ = makeController(params, artifact(), drive_);
  active_ = controller_ != nullptr;
}

void DiffDrive::setCommand(const Command& c) {
  if (const std::string why = refusal(c); !why.empty()) throw std::invalid_argument(why);
  level_ = c.level;
  active_ = false;  // a command from outside takes over
  if (c.level == CommandLevel::Wheels) {
    drive_.setWheels(c.left_wheel, c.right_wheel);
    return;
  }
  // the velocity's part along the heading now, and the yaw rate
  const double yaw = yawOf(artifact().root().pose().orientation);
  drive_.setTwist(c.velocity.x() * std::cos(yaw) + c.velocity.y() * std::sin(yaw), c.yaw_rate);
}

Setpoint DiffDrive::currentSetpoint() const {
  Setpoint s;
  s.position = artifact().root().pose().position;
  s.yaw = yawOf(artifact().root().pose().orientation);
  return s;
}

void DiffDrive::step(const StepInfo& info) {
  hold_.step(info);
  const double dt = toSeconds(info.period);
  if (active_) {
    GroundInputs in{artifact(), environment(), drive_, drive_.odometry(), random()};
    controller_->step(toSeconds(info.time), in);
  }
  drive_.apply(dt);
  drive_.measure(dt, random());
}

void DiffDrive::saveState(StateWriter& out) const {
  drive_.saveState(out);
  out.write(static_cast<std::uint8_t>(level_));
  out.write(active_);
  if (controller_) controller_->saveState(out);
}

void DiffDrive::loadState(StateReader& in) {
  drive_.loadState(in);
  level_ = static_cast<CommandLevel>(in.get<std::uint8_t>());
  in.read(active_);
  if (active_ && !controller_) throw StateError("diff_drive: the saved state has a controller this driver has not");
  if (controller_) controller_->loadState(in);
}

}  // namespace ssx::ground
