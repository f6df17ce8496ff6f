#pragma once
// The physics engine from Python: which one steps, exchanging it while the run goes on
// (Environment::switchPhysics), and the switches made so far.
#include <ssx/ssx.hpp>

#include <pybind11/pybind11.h>

#include <string>

namespace ssx_python {

namespace py = pybind11;

/// Binds the physics engine's methods on the Environment class (`E` has env() and guarded()).
template <class E>
void bindPhysics(py::class_<E>& cls) {
  cls.def(
         "switch_physics",
         [](E& e, const std::string& engine) { e.guarded([&] { e.env().switchPhysics(engine); }); },
         py::arg("engine"),
         "Continues the run on another physics engine (\"ode\", \"bullet\") from the next step: bodies, joints, "
         "attachments, ghosts and the robots' own state carry over, contacts are found again. Before the first step: "
         "the engine the run starts with. Raises for an unknown engine.")
      .def_property_readonly(
          "physics_engine",
          [](E& e) { return e.guarded([&] { return e.env().settings().physics.engine; }); },
          "The physics engine stepping now.")
      .def_property_readonly(
          "physics_switches",
          [](E& e) {
            py::list out;
            for (const ssx::PhysicsSwitch& x : e.guarded([&] { return e.env().physicsSwitches(); }))
              out.append(py::make_tuple(ssx::toSeconds(x.time), x.from, x.to));
            return out;
          },
          "The switches of physics engine so far: (time s, from, to) each, in order.");
}

}  // namespace ssx_python
