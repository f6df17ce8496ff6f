#pragma once
// Ghosts and operators from Python: a real robot's poses in (set_external_pose) and its status out;
// an operator's commands in (operator_command) and its force out (operator_force).
#include "convert.hpp"

#include <ssx/ssx.hpp>

#include <pybind11/pybind11.h>

#include <optional>
#include <string>

namespace ssx_python {

namespace py = pybind11;

/// Environment::setExternalPose from Python values: position (3), orientation (w, x, y, z) or None
/// (level), stamp (s) or None (now). ValueError for a bad shape, NaN, or a quaternion far from unit.
void setExternalPose(ssx::Environment& env, const std::string& name, const py::object& position,
                     const py::object& orientation, std::optional<double> stamp);
/// Environment::ghostStatus as a dict: lost, age, samples. KeyError for an unknown name.
py::dict ghostStatus(ssx::Environment& env, const std::string& name);
/// The operator extension `name` (KeyError when there is none).
ssx::OperatorInterface& operatorNamed(ssx::Environment& env, const std::string& name);
/// OperatorInterface::command from Python values: velocity (3), yaw rate.
void operatorCommand(ssx::Environment& env, const std::string& name, const py::object& velocity, double yaw_rate);

/// Binds the ghost and operator methods on the Environment class (`E` has env() and guarded()).
template <class E>
void bindGhostsAndOperators(py::class_<E>& cls) {
  cls.def(
         "set_external_pose",
         [](E& e, const std::string& artifact, const py::object& position, const py::object& orientation,
            std::optional<double> stamp) { e.guarded([&] { setExternalPose(e.env(), artifact, position, orientation, stamp); }); },
         py::arg("artifact"), py::arg("position"), py::arg("orientation") = py::none(), py::arg("stamp") = py::none(),
         "A pose of ghost `artifact` (<ghost/> in the scene: a real robot) measured at simulated time `stamp` (s; None: "
         "now): position (m, world), orientation (w, x, y, z; None: level). Samples may come late and out of order; "
         "each step uses their interpolation at its time.")
      .def(
          "ghost_status",
          [](E& e, const std::string& artifact) { return e.guarded([&] { return ghostStatus(e.env(), artifact); }); },
          py::arg("artifact"),
          "A ghost's status: lost (no pose yet, or none for longer than its timeout), age (s) of its newest pose, "
          "samples kept.")
      .def(
          "ghost_ages", [](E& e) { return e.guarded([&] { return ageDict(e.env().ghostAges()); }); },
          "The ages of the poses the ghosts were placed at, every step so far: count, median, p99, max (s).")
      .def(
          "operator_command",
          [](E& e, const std::string& name, const py::object& velocity, double yaw_rate) {
            e.guarded([&] { operatorCommand(e.env(), name, velocity, yaw_rate); });
          },
          py::arg("operator"), py::arg("velocity"), py::arg("yaw_rate") = 0.0,
          "Steers the robots of operator extension `operator` as one: velocity (m/s, 3) and yaw rate (rad/s) in its "
          "frame, clipped to its limits; held until the next command or its dead-man rule stops them.")
      .def(
          "operator_force",
          [](E& e, const std::string& name) { return e.guarded([&] { return vector3(operatorNamed(e.env(), name).force()); }); },
          py::arg("operator"), "The force (N, world frame, 3) operator `operator` should feel now, by its law.");
}

}  // namespace ssx_python
