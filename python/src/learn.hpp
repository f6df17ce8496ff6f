#pragma once
// ssx.learn's core from Python: ssx::VectorEnvironment (many copies of one scene stepped together
// on a pool of threads) as `ssx._ssx.VectorEnvironment`, read and commanded through numpy arrays.
// The Gymnasium and PettingZoo layers are Python (python/ssx/learn.py).
#include <ssx/environment.hpp>

#include <pybind11/pybind11.h>

#include <cstdint>

namespace ssx_python {

/// Adds the class VectorEnvironment to the module.
void bindVectorEnvironment(pybind11::module_& m);

/// The class VectorEnvironment, and on the Environment class (`E` has env() and guarded()) what a
/// learning loop on one environment needs besides save and restore: reseed.
template <class E>
void bindLearn(pybind11::module_& m, pybind11::class_<E>& environment) {
  bindVectorEnvironment(m);
  environment.def(
      "reseed",
      [](E& e, std::uint64_t seed) {
        e.guarded([&] {
          if (e.env().state() == ssx::Environment::State::Setup) e.env().start();
          e.env().reseed(seed);
        });
      },
      pybind11::arg("seed"),
      "Restarts every random stream (sensor noise, wind gusts) as a scene loaded with this seed would "
      "start it: after restore_state, so that episodes from one saved state draw other noise.");
}

}  // namespace ssx_python
