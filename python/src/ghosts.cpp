#include "ghosts.hpp"

#include "commands.hpp"

#include <stdexcept>

namespace ssx_python {

void setExternalPose(ssx::Environment& env, const std::string& name, const py::object& position,
                     const py::object& orientation, std::optional<double> stamp) {
  const Array xyz = requireRows(position, 3, 0, "position");
  ssx::Pose p;
  p.position = ssx::Vec3(xyz.at(0), xyz.at(1), xyz.at(2));
  if (!orientation.is_none()) {
    const Array q = requireRows(orientation, 4, 0, "orientation");
    p.orientation = ssx::Quat(q.at(0), q.at(1), q.at(2), q.at(3));
  }
  try {
    env.setExternalPose(name, p, stamp.value_or(ssx::toSeconds(env.time())));
  } catch (const std::invalid_argument& e) {
    throw py::value_error(std::string("ssx: set_external_pose: ") + e.what());
  }
}

py::dict ghostStatus(ssx::Environment& env, const std::string& name) {
  const ssx::Artifact* a = env.findArtifact(name);
  if (a == nullptr) throw py::key_error("ssx: no artifact named '" + name + "'");
  const ssx::Environment::GhostStatus s = env.ghostStatus(*a);
  py::dict d;
  d["lost"] = s.lost;
  d["age"] = s.age;
  d["samples"] = s.samples;
  return d;
}

ssx::OperatorInterface& operatorNamed(ssx::Environment& env, const std::string& name) {
  auto* op = dynamic_cast<ssx::OperatorInterface*>(env.extension(name));
  if (op == nullptr) throw py::key_error("ssx: no operator extension named '" + name + "'");
  return *op;
}

void operatorCommand(ssx::Environment& env, const std::string& name, const py::object& velocity, double yaw_rate) {
  const Array v = requireRows(velocity, 3, 0, "velocity");
  operatorNamed(env, name).command(ssx::Vec3(v.at(0), v.at(1), v.at(2)), yaw_rate);
}

}  // namespace ssx_python
