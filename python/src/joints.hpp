#pragma once
// Joints from Python: a physic node named "artifact" (its first root) or "artifact/node"; run-time
// joints (attach, release, detach, attachments) and the joints of node trees (position, velocity,
// motor commands).
#include <ssx/ssx.hpp>

#include <pybind11/pybind11.h>

#include <string>

namespace ssx_python {

namespace py = pybind11;

/// The node `path` names: "artifact" (its first physic root) or "artifact/node". KeyError when
/// there is no such artifact or node.
ssx::PhysicNode& nodeNamed(ssx::Environment& env, const std::string& path);

/// Binds the joint methods on the Environment class (`E` has env() and guarded()).
template <class E>
void bindJoints(py::class_<E>& cls) {
  // (a hold is made in a running world: the first one starts it, as set_commands does)
  auto started = [](E& e) -> ssx::Environment& {
    if (e.env().state() == ssx::Environment::State::Setup) e.env().start();
    return e.env();
  };
  cls.def(
         "attach",
         [started](E& e, const std::string& holder, const std::string& held) {
           e.guarded([&] {
             ssx::Environment& env = started(e);
             nodeNamed(env, holder).attach(nodeNamed(env, held));
           });
         },
         py::arg("holder"), py::arg("held"),
         "Holds node `held` by node `holder` with a fixed joint, as the two are now (a gripper closing): they move "
         "as one and do not collide. Nodes are 'artifact' (its first root) or 'artifact/node'. ssx.Error for two nodes "
         "of one body, a static holder or a ghost.")
      .def(
          "release",
          [started](E& e, const std::string& holder) { e.guarded([&] { nodeNamed(started(e), holder).release(); }); },
          py::arg("holder"), "Lets go of every body node `holder` holds (its attach calls).")
      .def(
          "detach",
          [started](E& e, const std::string& node) { e.guarded([&] { nodeNamed(started(e), node).detach(); }); },
          py::arg("node"), "Frees node `node`'s body of every run-time joint on it, whoever made it.")
      .def(
          "attachments",
          [](E& e, const std::string& node) { return e.guarded([&] { return nodeNamed(e.env(), node).attachments(); }); },
          py::arg("node"), "How many run-time joints hold node `node`'s body or are held by it.")
      .def(
          "joint_position",
          [](E& e, const std::string& node) { return e.guarded([&] { return nodeNamed(e.env(), node).jointPosition(); }); },
          py::arg("node"),
          "The position of the joint joining node `node` ('artifact/node', joint= in its artifact file) to its parent: "
          "rad (hinge) or m (slider); 0 before the first step.")
      .def(
          "joint_velocity",
          [](E& e, const std::string& node) { return e.guarded([&] { return nodeNamed(e.env(), node).jointVelocity(); }); },
          py::arg("node"), "That joint's velocity, rad/s or m/s.")
      .def(
          "set_joint_velocity",
          [started](E& e, const std::string& node, double velocity) {
            e.guarded([&] { nodeNamed(started(e), node).setJointVelocity(velocity); });
          },
          py::arg("node"), py::arg("velocity"),
          "Drives that joint's motor toward a velocity (rad/s or m/s) with at most its max_torque / max_force, held "
          "until changed (ssx.Error when it has no motor).")
      .def(
          "set_joint_position",
          [started](E& e, const std::string& node, double position) {
            e.guarded([&] { nodeNamed(started(e), node).setJointPosition(position); });
          },
          py::arg("node"), py::arg("position"), "Drives that joint's motor toward a position (rad or m), held until changed.");
}

}  // namespace ssx_python
