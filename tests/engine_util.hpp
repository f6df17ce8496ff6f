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

/// For an engine that keeps its settings typed: its declared defaults, configured into `start`
/// (typed settings set away from the defaults), and described back, give the values the typed
/// defaults describe to. Returns the declarations whose values differ (none: configure sets every
/// field from its declaration, describe reads every one back).
inline std::vector<std::string> typedDefaultsMismatch(const PhysicEngineClass& engine, PhysicsSettings start) {
  Descriptor defaults("physics");
  for (const ssx_plugin_param& p : engine.settings) defaults.set(p.name, p.default_value);
  engine.configure(defaults, start);
  Descriptor described("physics"), typed("physics");
  engine.describe(start, described);
  engine.describe(PhysicsSettings{}, typed);
  std::vector<std::string> differ;
  for (const ssx_plugin_param& p : engine.settings) {
    const auto* a = described.find(p.name);
    const auto* b = typed.find(p.name);
    if (a == nullptr || b == nullptr || a->value != b->value) differ.emplace_back(p.name);
  }
  return differ;
}

}  // namespace ssx::test
