// The viewer's scene shapes: a mesh drawn by several shapes is listed once, each shape naming it
// with its bounding box and reach; the mesh's vertices and triangles as written; poses composed
// down the tree.
#include "../../../../plugins/viewer/scene_shapes.hpp"

#include <catch2/catch.hpp>

#include <memory>
#include <string>

using namespace ssx;
using namespace ssx::viewer;
using Catch::Contains;

namespace {

// a tetrahedron 1 x 2 x 0.5 m from its origin
std::shared_ptr<const TriangleMesh> tetrahedron() {
  auto m = std::make_shared<TriangleMesh>();
  m->vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 2, 0), Vec3(0, 0, 0.5)};
  m->triangles = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  m->min = Vec3(0, 0, 0);
  m->max = Vec3(1, 2, 0.5);
  return m;
}

}  // namespace

TEST_CASE("viewer scene shapes: a mesh drawn twice is listed once, each shape naming it with its box", "[viewer]") {
  const auto mesh = tetrahedron();
  RenderNodeSpec root;
  root.primitive = RenderNodeSpec::Primitive::Box;
  root.size = Vec3(0.1, 0.2, 0.3);
  root.pose.position = Vec3(1, 0, 0);
  RenderNodeSpec a;
  a.primitive = RenderNodeSpec::Primitive::Mesh;
  a.mesh = mesh;
  a.pose.position = Vec3(0, 0, 2);
  RenderNodeSpec b = a;
  b.pose.position = Vec3(0, 3, 0);
  RenderNodeSpec none;  // a mesh node without its mesh draws nothing
  none.primitive = RenderNodeSpec::Primitive::Mesh;
  root.children = {a, b, none};

  std::string out;
  bool first = true;
  MeshTable table;
  shapes(out, root, Pose{}, first, table);
  CHECK_FALSE(first);
  REQUIRE(table.meshes.size() == 1);
  CHECK(table.meshes[0] == mesh.get());
  // three shapes: the box, then the mesh twice, posed down the tree
  CHECK(out.rfind(R"({"kind":"box","size":[0.1,0.2,0.3])", 0) == 0);
  CHECK_THAT(out, Contains(R"(},{"kind":"mesh","mesh":0,"reach":2.29129,"size":[1,2,0.5])"));
  CHECK_THAT(out, Contains(R"("pose":[1,0,2,0,0,0,1])"));
  CHECK_THAT(out, Contains(R"("pose":[1,3,0,0,0,0,1])"));
  std::size_t kinds = 0;
  for (auto at = out.find(R"("kind")"); at != std::string::npos; at = out.find(R"("kind")", at + 1)) ++kinds;
  CHECK(kinds == 3);
  CHECK(table.json() == R"([{"vertices":[0,0,0,1,0,0,0,2,0,0,0,0.5],"triangles":[0,2,1,0,1,3,0,3,2,1,2,3]}])");
  // another mesh after it: the second entry, a comma between
  RenderNodeSpec other = a;
  other.mesh = tetrahedron();
  first = true;
  std::string more;
  shapes(more, other, Pose{}, first, table);
  CHECK_THAT(more, Contains(R"("mesh":1)"));
  CHECK(table.json().find(R"(]},{"vertices":)") != std::string::npos);
  CHECK(MeshTable{}.json() == "[]");
}
