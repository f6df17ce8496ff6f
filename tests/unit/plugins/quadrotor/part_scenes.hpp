#pragma once
// What the tests of the quadrotor's parts share: scenes of mk_quads and boxes, quadrotors with
// noiseless sensors, the mk_quad's rotors, files written for a test.
#include "quadrotor_model.hpp"

#include <ssx/ssx.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace ssx::quadrotor::test {

inline const std::filesystem::path kArtifacts = std::filesystem::path(SSX_EXAMPLES_DIR) / "artifacts";

// a scene at 500 Hz over the ground, with the types q (mk_quad) and box declared
inline Scene sceneOf(const std::string& body, std::uint64_t seed = 1) {
  return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"" + std::to_string(seed) +
                                 "\"/><ground/><type name=\"q\" file=\"mk_quad.xml\"/>"
                                 "<type name=\"box\" file=\"box.xml\"/>" +
                                 body + "</scene>",
                             "parts.xml", kArtifacts);
}

// a plus-configuration of four rotors 0.225 m from the centre, as the mk_quad's
inline std::vector<Rotor> plus() {
  return {{Vec3(0.225, 0, 0), 1}, {Vec3(0, 0.225, 0), -1}, {Vec3(-0.225, 0, 0), 1}, {Vec3(0, -0.225, 0), -1}};
}

// an mk_quad with noiseless sensors, so that what moves it is what the test sets
inline std::string quad(const std::string& name, const std::string& xyz, const std::string& driver = "") {
  return "<artifact name=\"" + name + "\" type=\"q\" xyz=\"" + xyz + "\"><driver " + driver +
         "/><sensor index=\"0\" noise=\"false\"/><sensor index=\"1\" position_noise=\"0\" velocity_noise=\"0\"/>"
         "</artifact>";
}

inline std::filesystem::path writeFile(const std::string& name, const std::string& text) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace ssx::quadrotor::test
