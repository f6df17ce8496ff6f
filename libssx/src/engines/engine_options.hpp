#pragma once
// An engine's own settings (PhysicEngineClass::settings) out of what a <physics> element or a
// program gives: what the scene reader and createPhysicEngine both check.
#include <ssx/physic_engine.hpp>

#include <vector>

namespace ssx::detail {

// the settings `c` declares, taken from `given` (other attributes are not looked at), checked
// against the declarations (`problems`: what they refuse), every default filled in; the result is
// named for the engine (PhysicsSettings::options)
Descriptor engineOptions(const PhysicEngineClass& c, const Descriptor& given, std::vector<Diagnostic>& problems);

}  // namespace ssx::detail
