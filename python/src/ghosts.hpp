#pragma once
// Ghosts from Python: a real robot's poses in (set_external_pose), its status out.
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

}  // namespace ssx_python
