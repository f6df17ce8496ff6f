#pragma once
// The ODE backend of PhysicEngine. Private: nothing of ODE leaves libssx.

#include <ssx/physic_engine.hpp>

#include <ode/ode.h>

#include <vector>

namespace ssx::detail {

class OdeEngine final : public PhysicEngine {
 public:
  explicit OdeEngine(const PhysicsSettings& settings);
  ~OdeEngine() override;

  std::string name() const override { return "ode"; }
  int addBody(const MassProperties& mass, const std::vector<Shape>& shapes, const BodyState& state) override;
  void addStatic(const std::vector<Shape>& shapes, const Pose& pose) override;
  void step(Nanoseconds dt, std::span<const Wrench> wrenches) override;
  void readStates(std::span<BodyState> out) const override;
  void setState(int body, const BodyState& state) override;
  std::size_t bodyCount() const override { return bodies_.size(); }
  void saveState(StateWriter& out) const override;
  void restoreState(StateReader& in) override;
  std::size_t contactCount() const override { return contact_count_; }

 private:
  static void nearCallback(void* data, dGeomID a, dGeomID b);
  dGeomID createGeom(const Shape& shape);

  PhysicsSettings settings_;
  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contact_group_ = nullptr;
  std::vector<dBodyID> bodies_;
  std::vector<dContact> contact_scratch_;
  std::size_t contact_count_ = 0;
  unsigned long rand_seed_ = 0;  // this world's own copy of ODE's process-wide dRand seed
};

}  // namespace ssx::detail
