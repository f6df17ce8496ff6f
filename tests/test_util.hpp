#pragma once
// Helpers shared by the tests: small scenes built in code.

#include <ssx/ssx.hpp>

#include <functional>
#include <memory>

namespace ssx::test {

/// A driver that runs a function each step.
class LambdaDriver final : public Driver {
 public:
  explicit LambdaDriver(std::function<void(Driver&, const StepInfo&)> fn) : fn_(std::move(fn)) {}
  void step(const StepInfo& info) override { fn_(*this, info); }

 private:
  std::function<void(Driver&, const StepInfo&)> fn_;
};

/// A sensor that delivers the step it ran in.
class LambdaSensor final : public SensorOf<ClockMeasurement> {
 public:
  void sense(const StepInfo& info) override {
    output().stamp = info.time;
    output().step = info.step;
  }
};

/// A body made of one box, with explicit mass (and inertia if given).
inline PhysicNodeSpec boxBody(const Vec3& size, double mass, const Mat3* inertia = nullptr) {
  PhysicNodeSpec spec;
  spec.name = "body";
  spec.shapes.push_back(Shape::box(size));
  spec.mass = mass;
  if (inertia != nullptr) spec.inertia = *inertia;
  return spec;
}

inline Pose at(double x, double y, double z) { return {Vec3(x, y, z), Quat::Identity()}; }

}  // namespace ssx::test
