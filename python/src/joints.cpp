#include "joints.hpp"

namespace ssx_python {

ssx::PhysicNode& nodeNamed(ssx::Environment& env, const std::string& path) {
  const std::size_t slash = path.find('/');
  const std::string artifact = path.substr(0, slash);
  ssx::Artifact* a = env.findArtifact(artifact);
  if (a == nullptr) throw py::key_error("ssx: no artifact named '" + artifact + "'");
  if (slash == std::string::npos) {
    if (a->rootCount() == 0) throw py::key_error("ssx: artifact '" + artifact + "' has no physic node");
    return a->root();
  }
  const std::string node = path.substr(slash + 1);
  ssx::PhysicNode* n = a->node(node);
  if (n == nullptr) throw py::key_error("ssx: artifact '" + artifact + "' has no physic node named '" + node + "'");
  return *n;
}

}  // namespace ssx_python
