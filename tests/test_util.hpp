#pragma once
// Helpers shared by the tests: small scenes built in code.

#include <ssx/ssx.hpp>

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

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

/// A measurement that is a count.
struct Counter : Measurement {
  int value = 0;
};

/// A sensor that counts its own runs.
class CountingSensor final : public SensorOf<Counter> {
 public:
  void sense(const StepInfo& info) override {
    output().value += 1;
    output().stamp = info.time;
  }
};

/// A sensor that throws in step 2.
class ThrowingSensor final : public SensorOf<Counter> {
 public:
  void sense(const StepInfo& info) override {
    if (info.step == 2) throw std::runtime_error("lidar unplugged");
  }
};

/// A free 1 kg box of 10 cm at (x, 0, 1).
inline Artifact& addBall(Environment& env, const std::string& name, double x = 0) {
  Artifact& a = env.addArtifact(name, at(x, 0, 1));
  a.addPhysicRoot(boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
  return a;
}

}  // namespace ssx::test
