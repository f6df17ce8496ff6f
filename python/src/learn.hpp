#pragma once
// ssx.learn's core from Python: ssx::VectorEnvironment (many copies of one scene stepped together
// on a pool of threads) as `ssx._ssx.VectorEnvironment`, read and commanded through numpy arrays.
// The Gymnasium and PettingZoo layers are Python (python/ssx/learn.py).
#include <ssx/environment.hpp>

#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <utility>

namespace ssx_python {

/// Adds the class VectorEnvironment to the module.
void bindVectorEnvironment(pybind11::module_& m);

/// A variable (ssx/variation.hpp) as a dict: name, neutral, min, max, doc.
pybind11::dict variableDict(const ssx::Variable& v);
/// The contacts of an environment's last step as a list of (artifact a, artifact b or None for
/// the static world, impulse N s, position and normal (from b towards a) as
/// numpy arrays of 3, as the module gives vectors).
pybind11::list contactList(const ssx::Environment& env);
/// One kind of sensor of every robot of `env` (the artifacts whose driver takes set-points, in
/// artifact order), (robots, width) float64, into `out` when not None (ssx::readSensors).
pybind11::object readRobots(const ssx::Environment& env, const std::string& kind, const pybind11::object& out,
                            std::size_t slots);
/// Every robot's latest camera image, (robots, height, width, 3) uint8, into `out` when not None.
pybind11::object robotImages(const ssx::Environment& env, const pybind11::object& out);

/// The class VectorEnvironment, and on the Environment class (`E` has env() and guarded()) what a
/// learning loop on one environment needs besides save and restore: reseed, and the constants
/// varied between episodes (variables, vary, variation).
template <class E>
void bindLearn(pybind11::module_& m, pybind11::class_<E>& environment) {
  bindVectorEnvironment(m);
  auto artifact = [](E& e, const std::string& name) -> const ssx::Artifact& {
    const ssx::Artifact* a = std::as_const(e.env()).findArtifact(name);
    if (a == nullptr) throw pybind11::key_error("ssx: no artifact named '" + name + "'");
    return *a;
  };
  environment.def(
      "variables",
      [artifact](E& e, const std::string& robot) {
        pybind11::list out;
        for (const ssx::Variable& v : e.env().variables(artifact(e, robot))) out.append(variableDict(v));
        return out;
      },
      pybind11::arg("robot"),
      "The constants of a robot that vary() takes: dicts of name, neutral (the value as configured), min, max, doc.");
  environment.def(
      "vary",
      [artifact](E& e, const std::string& robot, const std::string& name, double value) {
        e.guarded([&] {
          if (e.env().state() == ssx::Environment::State::Setup) e.env().start();
          e.env().vary(artifact(e, robot), name, value);
        });
      },
      pybind11::arg("robot"), pybind11::arg("name"), pybind11::arg("value"),
      "Sets a constant of the robot from the next step on (domain randomisation): 'mass' and 'inertia' (factors on "
      "its bodies'), or a variable of its plugins (variables()). Part of the saved state.");
  environment.def(
      "read",
      [](E& e, const std::string& kind, const pybind11::object& out, std::size_t slots) {
        return e.guarded([&] { return readRobots(e.env(), kind, out, slots); });
      },
      pybind11::arg("kind"), pybind11::arg("out") = pybind11::none(), pybind11::arg("slots") = 0,
      "(robots, width): one kind of sensor of every robot (setpoint_names()), from its first sensor of the kind: "
      "pose, imu, proximity, ground, range, range_and_bearing or odometry (VectorEnvironment.read's layouts).");
  environment.def(
      "images",
      [](E& e, const pybind11::object& out) { return e.guarded([&] { return robotImages(e.env(), out); }); },
      pybind11::arg("out") = pybind11::none(),
      "(robots, height, width, 3) uint8: every robot's latest camera image (setpoint_names()), RGB, rows from the top.");
  environment.def(
      "record_contacts",
      [](E& e, bool on) { e.guarded([&] { e.env().recordContacts(on); }); }, pybind11::arg("on") = true,
      "Keeps the contacts of every step from now on (off by default); contact_list() lists the last step's.");
  environment.def(
      "contact_list", [](E& e) { return e.guarded([&] { return contactList(e.env()); }); },
      "The last step's contacts, one per pair touching: ssx.Contact(artifact, other, impulse N s, position, normal "
      "from other towards artifact, static), other the artifact touched (the ground or a wall when static). "
      "record_contacts() first.");
  environment.def(
      "variation",
      [artifact](E& e, const std::string& robot, const std::string& name) {
        return e.env().variation(artifact(e, robot), name);
      },
      pybind11::arg("robot"), pybind11::arg("name"), "The value vary() set (the neutral one when never varied).");
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
