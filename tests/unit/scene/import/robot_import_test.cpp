// What the importers share (robot_import.cpp): resources found relative to the description,
// through package:// and model:// on the search path and the environment's variables, with a
// message that says where it looked; poses written as xyz and rpy; the artifact printed with mesh
// paths relative to where it goes.
#include "scene/import/robot_import.hpp"

#include <ssx/scene_model.hpp>

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>

using namespace ssx;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

fs::path touch(const fs::path& p) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << "x";
  return p;
}

}  // namespace

TEST_CASE("resources: relative, package://, model:// and file://, and where they were looked for", "[import]") {
  const fs::path root = fs::current_path() / "robot_import_test";
  const fs::path mesh = touch(root / "share/my_robot/meshes/arm.stl");
  touch(root / "models/cf/meshes/body.dae");
  detail::ResourcePath path{{root / "share"}};
  std::string problem;
  CHECK(path.resolve("meshes/arm.stl", root / "share/my_robot", problem) == mesh);
  CHECK(path.resolve("package://my_robot/meshes/arm.stl", "/elsewhere", problem) == mesh);
  CHECK(path.resolve("file://" + mesh.string(), "/elsewhere", problem) == mesh);
  // a package folder listed itself
  detail::ResourcePath itself{{root / "share/my_robot"}};
  CHECK(itself.resolve("package://my_robot/meshes/arm.stl", "/elsewhere", problem) == mesh);
  // model:// through GZ_SIM_RESOURCE_PATH
  ::setenv("GZ_SIM_RESOURCE_PATH", (root / "models").c_str(), 1);
  CHECK(detail::ResourcePath{}.resolve("model://cf/meshes/body.dae", "/elsewhere", problem) == root / "models/cf/meshes/body.dae");
  ::unsetenv("GZ_SIM_RESOURCE_PATH");
  CHECK(detail::ResourcePath{}.resolve("model://cf/meshes/body.dae", "/elsewhere", problem).empty());
  CHECK_THAT(problem, Contains("'cf/meshes/body.dae' not found") && Contains("GZ_SIM_RESOURCE_PATH"));
  CHECK(path.resolve("meshes/none.stl", root, problem).empty());
  CHECK_THAT(problem, Contains("no file") && Contains("relative to the description"));
}

TEST_CASE("an imported pose reads back as the same pose, and the artifact prints meshes relative to it", "[import]") {
  const Pose p{Vec3(0.1, -0.2, 0.3), Quat(Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()))};
  Descriptor d("physic");
  detail::setPoseAttributes(d, p);
  const Pose back = poseFromXyzRpy(d.get<Vec3>("xyz"), d.get<Vec3>("rpy"));
  CHECK(back.position.isApprox(p.position));
  CHECK(back.orientation.angularDistance(p.orientation) < 1e-12);
  Descriptor none("physic");
  detail::setPoseAttributes(none, Pose{});
  CHECK(none.attributes().empty());

  Descriptor artifact("artifact");
  Descriptor& root = artifact.addChild(Descriptor("physic"));
  root.set("name", "a<b");
  root.addChild(Descriptor("mesh")).set("file", "/robots/r/meshes/m.stl");
  const std::string xml = detail::artifactXml(artifact, "/robots/r", "from r.urdf -- a test");
  CHECK_THAT(xml, Contains(R"(<mesh file="meshes/m.stl"/>)"));
  CHECK_THAT(xml, Contains(R"(name="a&lt;b")"));
  CHECK_THAT(xml, Contains("<!-- from r.urdf - - a test -->"));
  // outside the output's directory: absolute
  CHECK_THAT(detail::artifactXml(artifact, "/elsewhere", ""), Contains(R"(file="/robots/r/meshes/m.stl")"));
}
