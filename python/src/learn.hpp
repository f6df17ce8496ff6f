#pragma once
// ssx.learn's core from Python: ssx::VectorEnvironment (many copies of one scene stepped together
// on a pool of threads) as `ssx._ssx.VectorEnvironment`, read and commanded through numpy arrays.
// The Gymnasium and PettingZoo layers are Python (python/ssx/learn.py).
#include <pybind11/pybind11.h>

namespace ssx_python {

/// Adds the class VectorEnvironment to the module.
void bindLearn(pybind11::module_& m);

}  // namespace ssx_python
