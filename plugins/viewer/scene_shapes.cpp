// The viewer's scene message: shapes and meshes as JSON (scene_shapes.hpp).
#include "scene_shapes.hpp"

#include "frame.hpp"

#include <cstdint>
#include <cstdio>

namespace ssx::viewer {

namespace {

const char* kindName(RenderNodeSpec::Primitive p) {
  switch (p) {
    case RenderNodeSpec::Primitive::Box: return "box";
    case RenderNodeSpec::Primitive::Sphere: return "sphere";
    case RenderNodeSpec::Primitive::Cylinder: return "cylinder";
    case RenderNodeSpec::Primitive::Capsule: return "capsule";
    case RenderNodeSpec::Primitive::Plane: return "plane";
    case RenderNodeSpec::Primitive::Mesh: return "mesh";
    case RenderNodeSpec::Primitive::None: break;
  }
  return "";
}

}  // namespace

std::size_t MeshTable::of(const TriangleMesh* mesh) {
  const auto [it, fresh] = index.try_emplace(mesh, meshes.size());
  if (fresh) meshes.push_back(mesh);
  return it->second;
}

std::string MeshTable::json() const {
  std::string out = "[";
  char text[32];
  for (const TriangleMesh* m : meshes) {
    out += out.size() > 1 ? R"(,{"vertices":[)" : R"({"vertices":[)";
    for (const Vec3& v : m->vertices) {
      for (int k = 0; k < 3; ++k) {
        const int n = std::snprintf(text, sizeof text, "%.6g,", v[k]);
        out.append(text, static_cast<std::size_t>(n));
      }
    }
    if (!m->vertices.empty()) out.pop_back();
    out += R"(],"triangles":[)";
    for (const std::uint32_t i : m->triangles) out += std::to_string(i), out += ',';
    if (!m->triangles.empty()) out.pop_back();
    out += "]}";
  }
  return out + "]";
}

void shapes(std::string& out, const RenderNodeSpec& n, const Pose& parent, bool& first, MeshTable& meshes) {
  const Pose pose = parent * n.pose;
  if (n.primitive != RenderNodeSpec::Primitive::None &&
      (n.primitive != RenderNodeSpec::Primitive::Mesh || n.mesh != nullptr)) {
    const bool mesh = n.primitive == RenderNodeSpec::Primitive::Mesh;
    const Vec3 size = mesh ? Vec3(n.mesh->max - n.mesh->min) : n.size;
    out += first ? "" : ",";
    first = false;
    out += R"({"kind":")";
    out += kindName(n.primitive);
    if (mesh) {
      out += R"(","mesh":)" + std::to_string(meshes.of(n.mesh.get()));
      // how far it reaches from its origin
      out += R"(,"reach":)";
      appendNumber(out, n.mesh->min.cwiseAbs().cwiseMax(n.mesh->max.cwiseAbs()).norm());
      out += R"(,"size":[)";
    } else {
      out += R"(","size":[)";
    }
    appendNumber(out, size.x()), out += ',', appendNumber(out, size.y()), out += ',', appendNumber(out, size.z());
    out += R"(],"radius":)";
    appendNumber(out, n.radius);
    out += R"(,"length":)";
    appendNumber(out, n.length);
    out += R"(,"grid":)";
    out += n.grid ? "true" : "false";
    out += R"(,"color":[)";
    for (int k = 0; k < 4; ++k) appendNumber(out, n.color[static_cast<std::size_t>(k)]), out += k < 3 ? "," : "";
    out += R"(],"pose":[)";
    const Quat& q = pose.orientation;
    for (const double v : {pose.position.x(), pose.position.y(), pose.position.z(), q.x(), q.y(), q.z(), q.w()})
      appendNumber(out, v), out += ',';
    out.back() = ']';
    out += '}';
  }
  for (const auto& c : n.children) shapes(out, c, pose, first, meshes);
}

}  // namespace ssx::viewer
