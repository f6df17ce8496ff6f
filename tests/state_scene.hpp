#pragma once
// The scene the save-and-restore tests use (tests/unit/world_state_test.cpp, tests/integration/state_test.cpp).
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <string>

namespace ssx::test {

// quadrotors with noisy IMUs take off from the ground and fly the formation around a pillar,
// while boxes fall on the ground and on each other: contacts, noise, neighbours, obstacles
inline std::string stateSceneXml(int threads, const std::string& log = "", const std::string& engine = "ode") {
  return "<scene><environment timestep=\"0.002\" seed=\"11\" threads=\"" + std::to_string(threads) +
         "\"/><physics engine=\"" + engine + "\"/>"
         "<type name=\"quad\" file=\"" + (kArtifacts / "mk_quad_formation.xml").string() +
         "\"/><type name=\"box\" file=\"" + (kArtifacts / "box.xml").string() + "\"/><ground/>"
         "<obstacle name=\"pillar\" xyz=\"2.5 0 2\"><cylinder radius=\"0.25\" length=\"4\"/></obstacle>"
         "<swarm type=\"quad\" count=\"12\" layout=\"random\" min=\"-2 -2 0.05\" max=\"2 2 0.05\" "
         "min_distance=\"1.0\"><driver formation_index=\"{i}\" formation_size=\"12\" formation_radius=\"1.5\" "
         "formation_center=\"0 0 2.5\" offset=\"0 0 1\" start_time=\"0.3\"/></swarm>"
         "<swarm type=\"box\" name=\"box{i}\" count=\"12\" layout=\"random\" min=\"4 -0.3 0.2\" max=\"4.6 0.3 2.5\" "
         "min_distance=\"0.3\"/>" +
         (log.empty() ? std::string() : "<extension name=\"log\" plugin=\"csv_logger\" file=\"" + log + "\" rate_hz=\"20\"/>") +
         "</scene>";
}

inline Scene loadStateScene(int threads, const std::string& log = "", const std::string& engine = "ode") {
  return loadSceneFromString(stateSceneXml(threads, log, engine), "state.xml", kArtifacts);
}

}  // namespace ssx::test
