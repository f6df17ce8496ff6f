#pragma once
// ssx.Recording: a recording read back, as numpy arrays and Python values.
#include <pybind11/pybind11.h>

namespace ssx_python {

/// Adds the class Recording to the module.
void bindRecording(pybind11::module_& m);

}  // namespace ssx_python
