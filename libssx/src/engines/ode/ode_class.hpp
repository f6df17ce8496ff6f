#pragma once
// ODE's entry in the engine registry (engines.cpp registers it).
#include <ssx/physic_engine.hpp>

namespace ssx::detail {

PhysicEngineClass odeEngineClass();

}  // namespace ssx::detail
