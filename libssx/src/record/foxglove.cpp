// Foxglove's well-known schemas, JSON-encoded (record/foxglove.hpp).
#include "record/foxglove.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <map>
#include <utility>

namespace ssx::detail {

namespace {

// the pieces the schemas share
#define SSX_JSON_TIME R"j({"type":"object","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0,"maximum":999999999}}})j"
#define SSX_JSON_VEC3 R"j({"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}})j"
#define SSX_JSON_QUAT \
  R"j({"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}})j"
#define SSX_JSON_POSE R"j({"type":"object","properties":{"position":)j" SSX_JSON_VEC3 R"j(,"orientation":)j" SSX_JSON_QUAT "}}"
#define SSX_JSON_COLOR \
  R"j({"type":"object","properties":{"r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"}}})j"
#define SSX_JSON_SHAPE R"j({"type":"object","properties":{"pose":)j" SSX_JSON_POSE R"j(,"size":)j" SSX_JSON_VEC3 R"j(,"color":)j" SSX_JSON_COLOR

// "name":{"k1":v1,"k2":v2,...}
void appendObject(std::string& out, const char* name, std::initializer_list<std::pair<const char*, double>> fields) {
  out += '"';
  out += name;
  out += "\":{";
  bool first = true;
  for (const auto& [key, value] : fields) {
    out += first ? "\"" : ",\"";
    first = false;
    out += key;
    out += "\":";
    appendNumber(out, value);
  }
  out += '}';
}

void appendVec(std::string& out, const char* name, double x, double y, double z) {
  appendObject(out, name, {{"x", x}, {"y", y}, {"z", z}});
}

void appendQuat(std::string& out, const char* name, double w, double x, double y, double z) {
  appendObject(out, name, {{"x", x}, {"y", y}, {"z", z}, {"w", w}});
}

void appendTime(std::string& out, Nanoseconds time) {
  const Nanoseconds t = std::max<Nanoseconds>(0, time);
  out += R"j("timestamp":{"sec":)j" + std::to_string(t / 1'000'000'000) + R"j(,"nsec":)j" +
         std::to_string(t % 1'000'000'000) + "}";
}

void appendPose(std::string& out, const Pose& pose) {
  out += R"j("pose":{)j";
  appendVec(out, "position", pose.position.x(), pose.position.y(), pose.position.z());
  out += ',';
  const Quat& q = pose.orientation;
  appendQuat(out, "orientation", q.w(), q.x(), q.y(), q.z());
  out += '}';
}

// one primitive: {"pose":...,"size":...,"color":...[extra]}
void appendShape(std::string& out, const Pose& pose, const Vec3& size, const Color& color, const char* extra = "") {
  out += '{';
  appendPose(out, pose);
  out += ',';
  appendVec(out, "size", size.x(), size.y(), size.z());
  out += ',';
  appendObject(out, "color", {{"r", color[0]}, {"g", color[1]}, {"b", color[2]}, {"a", color[3]}});
  out += extra;
  out += '}';
}

// a mesh as a foxglove.TriangleListPrimitive: its vertices once, and three indices per triangle
void appendTriangles(std::string& out, const Pose& pose, const TriangleMesh& mesh, const Color& color) {
  out += '{';
  appendPose(out, pose);
  out += R"j(,"points":[)j";
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (i > 0) out += ',';
    const Vec3& v = mesh.vertices[i];
    out += R"j({"x":)j", appendNumber(out, v.x()), out += R"j(,"y":)j", appendNumber(out, v.y());
    out += R"j(,"z":)j", appendNumber(out, v.z()), out += '}';
  }
  out += "],";
  appendObject(out, "color", {{"r", color[0]}, {"g", color[1]}, {"b", color[2]}, {"a", color[3]}});
  out += R"j(,"colors":[],"indices":[)j";
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    if (i > 0) out += ',';
    out += std::to_string(mesh.triangles[i]);
  }
  out += "]}";
}

struct Primitives {
  std::string cubes, spheres, cylinders, triangles;
  static void add(std::string& list, auto&& write) {
    if (!list.empty()) list += ',';
    write(list);
  }
};

}  // namespace

const char* const kFrameTransformsSchema =
    R"j({"title":"foxglove.FrameTransforms","description":"transforms from the world to each recorded body (ssx)","type":"object",)j"
    R"j("properties":{"transforms":{"type":"array","items":{"title":"foxglove.FrameTransform","type":"object","properties":{)j"
    R"j("timestamp":)j" SSX_JSON_TIME R"j(,"parent_frame_id":{"type":"string"},"child_frame_id":{"type":"string"},)j"
    R"j("translation":)j" SSX_JSON_VEC3 R"j(,"rotation":)j" SSX_JSON_QUAT "}}}}}";

const char* const kSceneUpdateSchema =
    R"j({"title":"foxglove.SceneUpdate","description":"the shapes of the scene, one entity per recorded body and one for the world (ssx)","type":"object",)j"
    R"j("properties":{"deletions":{"type":"array","items":{"type":"object","properties":{"timestamp":)j" SSX_JSON_TIME
    R"j(,"type":{"type":"integer"},"id":{"type":"string"}}}},"entities":{"type":"array","items":{"title":"foxglove.SceneEntity","type":"object","properties":{)j"
    R"j("timestamp":)j" SSX_JSON_TIME R"j(,"frame_id":{"type":"string"},"id":{"type":"string"},)j"
    R"j("lifetime":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},"frame_locked":{"type":"boolean"},)j"
    R"j("cubes":{"type":"array","items":)j" SSX_JSON_SHAPE R"j(}}},"spheres":{"type":"array","items":)j" SSX_JSON_SHAPE
    R"j(}}},"cylinders":{"type":"array","items":)j" SSX_JSON_SHAPE
    R"j(,"bottom_scale":{"type":"number"},"top_scale":{"type":"number"}}}},)j"
    R"j("triangles":{"type":"array","items":{"type":"object","properties":{"pose":)j" SSX_JSON_POSE
    R"j(,"points":{"type":"array","items":)j" SSX_JSON_VEC3 R"j(},"color":)j" SSX_JSON_COLOR
    R"j(,"colors":{"type":"array"},"indices":{"type":"array","items":{"type":"integer","minimum":0}}}}}}}}}})j";

std::string frameTransforms(Nanoseconds time, std::span<const std::string> names, std::span<const float> positions,
                            std::span<const float> orientations) {
  std::string stamp;
  appendTime(stamp, time);
  std::string out = R"j({"transforms":[)j";
  out.reserve(names.size() * 220);
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += ',';
    out += '{';
    out += stamp;
    out += R"j(,"parent_frame_id":")j";
    out += kWorldFrame;
    out += R"j(","child_frame_id":)j";
    appendString(out, names[i]);
    out += ',';
    const float* p = &positions[3 * i];
    appendVec(out, "translation", p[0], p[1], p[2]);
    out += ',';
    const float* q = &orientations[4 * i];
    appendQuat(out, "rotation", q[0], q[1], q[2], q[3]);
    out += '}';
  }
  out += "]}";
  return out;
}

std::string sceneUpdate(Nanoseconds time, std::span<const SceneShape> shapes) {
  std::map<std::string, Primitives> frames;  // sorted: the entities in a stable order
  using P = RenderNodeSpec::Primitive;
  for (const SceneShape& s : shapes) {
    const RenderNodeSpec& n = *s.spec;
    if (n.primitive == P::None) continue;
    Primitives& f = frames[s.frame];
    const double d = 2 * n.radius;
    switch (n.primitive) {
      case P::Box:
        Primitives::add(f.cubes, [&](std::string& o) { appendShape(o, s.pose, n.size, n.color); });
        break;
      case P::Plane:
        Primitives::add(f.cubes, [&](std::string& o) {
          // a thin slab just below the plane, so that what stands on it is not hidden
          Pose slab = s.pose;
          slab.position = s.pose.transformPoint(Vec3(0, 0, -0.0005));
          appendShape(o, slab, Vec3(n.size.x(), n.size.y(), 0.001), n.color);
        });
        break;
      case P::Sphere:
        Primitives::add(f.spheres, [&](std::string& o) { appendShape(o, s.pose, Vec3(d, d, d), n.color); });
        break;
      case P::Cylinder:
      case P::Capsule:
        Primitives::add(f.cylinders, [&](std::string& o) {
          appendShape(o, s.pose, Vec3(d, d, n.length), n.color, R"j(,"bottom_scale":1,"top_scale":1)j");
        });
        if (n.primitive == P::Capsule)
          for (const double end : {-0.5, 0.5}) {
            Pose cap = s.pose;
            cap.position = s.pose.transformPoint(Vec3(0, 0, end * n.length));
            Primitives::add(f.spheres, [&](std::string& o) { appendShape(o, cap, Vec3(d, d, d), n.color); });
          }
        break;
      case P::Mesh:
        if (n.mesh != nullptr)
          Primitives::add(f.triangles, [&](std::string& o) { appendTriangles(o, s.pose, *n.mesh, n.color); });
        break;
      case P::None:
        break;
    }
  }
  std::string out = R"j({"deletions":[],"entities":[)j";
  bool first = true;
  for (const auto& [frame, p] : frames) {
    if (!first) out += ',';
    first = false;
    out += '{';
    appendTime(out, time);
    out += R"j(,"frame_id":)j";
    appendString(out, frame);
    out += R"j(,"id":)j";
    appendString(out, frame);
    out += R"j(,"lifetime":{"sec":0,"nsec":0},"frame_locked":true,"cubes":[)j" + p.cubes + R"j(],"spheres":[)j" +
           p.spheres + R"j(],"cylinders":[)j" + p.cylinders + R"j(],"triangles":[)j" + p.triangles + "]}";
  }
  out += "]}";
  return out;
}

}  // namespace ssx::detail
