#pragma once
// Bullet's entry in the engine registry (engines.cpp registers it).
#include <ssx/physic_engine.hpp>

namespace ssx::detail {

PhysicEngineClass bulletEngineClass();

}  // namespace ssx::detail
