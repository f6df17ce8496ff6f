#pragma once
// Helpers for tests of one physics engine through ssx::PhysicEngine, without an environment.
#include <ssx/physic_engine.hpp>
#include <ssx/physic_node.hpp>
#include <ssx/state.hpp>

#include <memory>
#include <string>
#include <vector>

namespace ssx::test {

inline std::unique_ptr<PhysicEngine> makeEngine(const std::string& name, PhysicsSettings settings = {}) {
  settings.engine = name;
  return createPhysicEngine(settings);
}

/// A box of `size` and `mass` (the inertia of a uniform box) at `position`, at rest.
inline int addBox(PhysicEngine& engine, const Vec3& size, double mass, const Vec3& position) {
  PhysicNodeSpec spec;
  spec.name = "box";
  spec.shapes.push_back(Shape::box(size));
  spec.mass = mass;
  BodyState state;
  state.pose.position = position;
  return engine.addBody(combinedMass(spec), spec.shapes, state);
}

inline std::vector<BodyState> states(const PhysicEngine& engine) {
  std::vector<BodyState> out(engine.bodyCount());
  engine.readStates(out);
  return out;
}

inline std::vector<std::byte> saved(const PhysicEngine& engine) {
  std::vector<std::byte> bytes;
  StateWriter out(bytes);
  engine.saveState(out);
  return bytes;
}

}  // namespace ssx::test
