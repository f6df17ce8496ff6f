#pragma once
// Commands from Python: set_commands at the five command levels and set_setpoints, each checked
// whole (shapes, NaN, what each robot takes) before any robot gets a row.
#include <ssx/ssx.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

namespace ssx_python {

namespace py = pybind11;
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// rows x cols of float64, C order, finite (cols 0: a vector of `rows`); `what` names it in errors
Array requireRows(const py::handle& value, py::ssize_t rows, py::ssize_t cols, const char* what);

/// The artifacts whose driver follows set-points, in artifact order: the rows of set_setpoints and
/// set_commands.
class CommandTargets {
 public:
  explicit CommandTargets(ssx::Environment& env);
  std::size_t size() const { return artifacts_.size(); }
  std::vector<std::string> names() const;
  /// `robots`: None (every target, in order) or a sequence of names or indices into names().
  std::vector<std::size_t> select(const py::handle& robots) const;
  void setCommands(const std::string& level, const py::handle& values, const py::handle& robots);
  void setSetpoints(const py::handle& positions, const py::handle& velocities, const py::handle& yaws,
                    const py::handle& accelerations, const py::handle& yaw_rates, const py::handle& robots);

 private:
  std::vector<ssx::Artifact*> artifacts_;
  std::vector<ssx::SetpointInterface*> setpoint_;
  std::vector<ssx::CommandInterface*> command_;  // nullptr where the driver takes set-points only
};

}  // namespace ssx_python
