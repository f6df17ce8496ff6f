// The osmesa render engine: Mesa's software OpenGL (llvmpipe) into a memory buffer, no display.
//
// One OpenGL 3.3 core context, created on the first draw, on the thread that draws (the thread
// calling Environment::step). Every primitive kind is a unit mesh, spheres and cylinders in four
// levels of detail. What appears large (full detail) is drawn instanced: one record per primitive
// (position, orientation, scale, colour), one call per mesh, lit per pixel. What appears small is
// placed and lit per vertex here and drawn as one vertex array in one call (llvmpipe shades each
// instance's few vertices as a batch of their own: with thousands of robots that per-instance cost
// was most of a frame). Primitives outside the view or smaller than a quarter pixel are left out;
// the coarser a polygon, the larger it is made, so that what a person sees covers the true area;
// boxes and cylinders thinner than a pixel are drawn as one face. Lighting: a sun from above plus a
// light at the eye, and a 1 m grid on ground planes. Shadows (when the view asks): one dark disc
// per robot on the ground, straight below it, as wide as the robot and fading with its height,
// blended over the ground last.
#include "render/osmesa_engine.hpp"
#include "render/gl_programs.hpp"
#include "render/osmesa_shaders.hpp"
#include "render/unit_meshes.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include <ssx/artifact.hpp>
#include <ssx/error.hpp>
#include <ssx/physic_node.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace ssx::detail {

namespace {

// one instance: position, rotation quaternion (x y z w), scale, colour, grid flag
struct Instance {
  float position[3], rotation[4], scale[3], color[4], grid;
};

// spheres and cylinders in four levels of detail, chosen by the size they appear in the image
enum Mesh {
  kBox,
  kSphere, kSphereMid, kSphereLow, kSphereTiny,
  kCylinder, kCylinderMid, kCylinderLow, kCylinderTiny,
  kDisc, kDiscMid, kDiscLow, kDiscTiny,  // a cylinder thinner than a pixel: one face, seen from both sides
  kPlane,  // also a box thinner than a pixel: its largest face
  kMeshCount
};
constexpr bool twoSided(int mesh) { return mesh == kPlane || (mesh >= kDisc && mesh <= kDiscTiny); }
// every face flat: one normal at all three corners of each triangle
constexpr bool flatFaces(int mesh) { return mesh == kBox || twoSided(mesh); }

// a vertex placed in the world, with its lit colour
struct BatchVertex {
  float position[3];
  std::uint8_t color[4];
};

const Vec3 kSun = Vec3(0.35, 0.25, 0.9).normalized();  // towards the sun (unit)

// column-major 4x4 product
std::array<float, 16> multiply(const std::array<float, 16>& a, const std::array<float, 16>& b) {
  std::array<float, 16> r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a[static_cast<std::size_t>(k * 4 + row)] * b[static_cast<std::size_t>(c * 4 + k)];
      r[static_cast<std::size_t>(c * 4 + row)] = s;
    }
  return r;
}

}  // namespace

struct OsmesaRenderEngine::Gl {
  OSMesaContext context = nullptr;
  std::vector<std::uint8_t> buffer;  // RGBA, bottom row first
  int width = 0, height = 0;
  GLuint vao[kMeshCount] = {}, vertex_buffer[kMeshCount] = {}, index_buffer[kMeshCount] = {},
         instance_buffer[kMeshCount] = {};
  GLsizei index_count[kMeshCount] = {};
  std::size_t instance_capacity[kMeshCount] = {};
  // the instanced programs: [0] smooth faces, [1] flat faces (flatFaces)
  GLuint program[2] = {};
  GLint u_view_projection[2] = {-1, -1}, u_sun[2] = {-1, -1}, u_eye[2] = {-1, -1};
  GLuint batch_program = 0;
  GLint batch_view_projection = -1;
  std::vector<Instance> instances[kMeshCount];
  // every mesh's vertices and triangles, for the batches
  std::vector<Vertex> mesh_vertices[kMeshCount];
  std::vector<unsigned> mesh_indices[kMeshCount];
  // the scene's own meshes (RenderNodeSpec::Primitive::Mesh), flat-shaded: each triangle its
  // three corners with the face's normal; made on first sight, kept (and the meshes with them)
  struct UserMesh {
    std::vector<Vertex> vertices;
    std::vector<unsigned> indices;
  };
  std::map<std::shared_ptr<const TriangleMesh>, UserMesh> user_meshes;
  // the batches: [0] one-sided, [1] seen from both sides, [2] the shadows (blended, drawn last)
  static constexpr int kBatches = 3, kShadowBatch = 2;
  GLuint batch_vao[kBatches] = {}, batch_vertex_buffer[kBatches] = {}, batch_index_buffer[kBatches] = {};
  std::size_t batch_vertex_capacity[kBatches] = {}, batch_index_capacity[kBatches] = {};
  std::vector<BatchVertex> batch_vertices[kBatches];
  std::vector<unsigned> batch_indices[kBatches];
  std::vector<float> depth;
};

OsmesaRenderEngine::OsmesaRenderEngine() : gl_(std::make_unique<Gl>()) {}

OsmesaRenderEngine::~OsmesaRenderEngine() {
  if (gl_->context != nullptr) OSMesaDestroyContext(gl_->context);
}

void OsmesaRenderEngine::makeCurrent(int width, int height) {
  Gl& g = *gl_;
  if (g.context == nullptr) {
    // (the process settings that make llvmpipe fast, LP_NUM_THREADS=0 and a large malloc trim
    // threshold, are the program's to choose: the ssx command sets them, see docs/library.md, Rendering)
    const int attributes[] = {OSMESA_FORMAT,
                              OSMESA_RGBA,
                              OSMESA_DEPTH_BITS,
                              24,
                              OSMESA_PROFILE,
                              OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION,
                              3,
                              OSMESA_CONTEXT_MINOR_VERSION,
                              3,
                              0};
    g.context = OSMesaCreateContextAttribs(attributes, nullptr);
    if (g.context == nullptr)
      throw Error("osmesa renderer: cannot create an OpenGL 3.3 core context (is Mesa's libOSMesa working?)");
  }
  if (width != g.width || height != g.height || OSMesaGetCurrentContext() != g.context) {
    g.buffer.assign(static_cast<std::size_t>(width) * height * 4, 0);
    if (!OSMesaMakeCurrent(g.context, g.buffer.data(), GL_UNSIGNED_BYTE, width, height))
      throw Error("osmesa renderer: cannot bind the context to a " + std::to_string(width) + "x" +
                  std::to_string(height) + " buffer");
    g.width = width;
    g.height = height;
  }
  if (g.batch_program == 0) setup();
}

void OsmesaRenderEngine::setup() {
  Gl& g = *gl_;
  for (int f = 0; f < 2; ++f) {
    g.program[f] = link(f == 0 ? shaders::kSmoothFaces : shaders::kFlatFaces, shaders::kVertexShader, shaders::kFragmentShader);
    g.u_view_projection[f] = glGetUniformLocation(g.program[f], "u_view_projection");
    g.u_sun[f] = glGetUniformLocation(g.program[f], "u_sun");
    g.u_eye[f] = glGetUniformLocation(g.program[f], "u_eye");
  }
  g.batch_program = link("", shaders::kBatchVertexShader, shaders::kBatchFragmentShader);
  g.batch_view_projection = glGetUniformLocation(g.batch_program, "u_view_projection");

  glGenVertexArrays(kMeshCount, g.vao);
  glGenBuffers(kMeshCount, g.vertex_buffer);
  glGenBuffers(kMeshCount, g.index_buffer);
  glGenBuffers(kMeshCount, g.instance_buffer);
  for (int m = 0; m < kMeshCount; ++m) {
    std::vector<Vertex> vertices;
    std::vector<unsigned> indices;
    switch (m) {
      case kBox: boxMesh(vertices, indices); break;
      case kSphere: sphereMesh(vertices, indices, 12, 20); break;
      case kSphereMid: sphereMesh(vertices, indices, 6, 10); break;
      case kSphereLow: sphereMesh(vertices, indices, 4, 6); break;
      case kSphereTiny: sphereMesh(vertices, indices, 2, 4); break;
      case kCylinder: cylinderMesh(vertices, indices, 20); break;
      case kCylinderMid: cylinderMesh(vertices, indices, 10); break;
      case kCylinderLow: cylinderMesh(vertices, indices, 6); break;
      case kCylinderTiny: cylinderMesh(vertices, indices, 4); break;
      case kDisc: discMesh(vertices, indices, 20); break;
      case kDiscMid: discMesh(vertices, indices, 10); break;
      case kDiscLow: discMesh(vertices, indices, 6); break;
      case kDiscTiny: discMesh(vertices, indices, 4); break;
      default: planeMesh(vertices, indices); break;
    }
    g.index_count[m] = static_cast<GLsizei>(indices.size());
    g.mesh_vertices[m] = vertices;
    g.mesh_indices[m] = indices;
    glBindVertexArray(g.vao[m]);
    glBindBuffer(GL_ARRAY_BUFFER, g.vertex_buffer[m]);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(),
                 GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, position)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, normal)));
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.index_buffer[m]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(unsigned)), indices.data(),
                 GL_STATIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, g.instance_buffer[m]);
    struct Attribute {
      GLuint location;
      GLint size;
      std::size_t offset;
    };
    for (const Attribute& a : {Attribute{2, 3, offsetof(Instance, position)}, Attribute{3, 4, offsetof(Instance, rotation)},
                               Attribute{4, 3, offsetof(Instance, scale)}, Attribute{5, 4, offsetof(Instance, color)},
                               Attribute{6, 1, offsetof(Instance, grid)}}) {
      glEnableVertexAttribArray(a.location);
      glVertexAttribPointer(a.location, a.size, GL_FLOAT, GL_FALSE, sizeof(Instance), reinterpret_cast<void*>(a.offset));
      glVertexAttribDivisor(a.location, 1);
    }
  }
  // the batches: world positions and lit colours
  glGenVertexArrays(Gl::kBatches, g.batch_vao);
  glGenBuffers(Gl::kBatches, g.batch_vertex_buffer);
  glGenBuffers(Gl::kBatches, g.batch_index_buffer);
  for (int b = 0; b < Gl::kBatches; ++b) {
    glBindVertexArray(g.batch_vao[b]);
    glBindBuffer(GL_ARRAY_BUFFER, g.batch_vertex_buffer[b]);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.batch_index_buffer[b]);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(BatchVertex), reinterpret_cast<void*>(offsetof(BatchVertex, position)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(BatchVertex), reinterpret_cast<void*>(offsetof(BatchVertex, color)));
  }
  glBindVertexArray(0);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
}

void OsmesaRenderEngine::renderView(const CameraView& view, const std::vector<RenderNode>& nodes,
                                    const Color& background, Image& out) {
  if (view.width <= 0 || view.height <= 0 || view.width > kMaxImageSide || view.height > kMaxImageSide)
    throw Error("osmesa renderer: image size " + std::to_string(view.width) + "x" + std::to_string(view.height) +
                " is out of range (1..16384)");
  makeCurrent(view.width, view.height);
  Gl& g = *gl_;

  // view: the camera looks along its +x with +z up; OpenGL's eye looks along -z with +y up
  const Eigen::Matrix3d r = view.pose.orientation.toRotationMatrix();
  const Vec3 forward = r.col(0), left = r.col(1), up = r.col(2), eye = view.pose.position;
  const Vec3 right = -left;
  std::array<float, 16> v{};
  for (int k = 0; k < 3; ++k) {
    v[static_cast<std::size_t>(k * 4 + 0)] = static_cast<float>(right[k]);
    v[static_cast<std::size_t>(k * 4 + 1)] = static_cast<float>(up[k]);
    v[static_cast<std::size_t>(k * 4 + 2)] = static_cast<float>(-forward[k]);
  }
  v[12] = static_cast<float>(-right.dot(eye));
  v[13] = static_cast<float>(-up.dot(eye));
  v[14] = static_cast<float>(forward.dot(eye));
  v[15] = 1;
  const double aspect = static_cast<double>(view.width) / view.height;
  const double tx = std::tan(view.fov_deg * std::numbers::pi / 360.0), ty = tx / aspect;
  const double n = view.near, f = view.far;
  std::array<float, 16> p{};
  p[0] = static_cast<float>(1 / tx);
  p[5] = static_cast<float>(1 / ty);
  p[10] = static_cast<float>(-(f + n) / (f - n));
  p[11] = -1;
  p[14] = static_cast<float>(-2 * f * n / (f - n));
  const std::array<float, 16> vp = multiply(p, v);

  // instances, by mesh: what the camera cannot see is left out, and spheres and cylinders are
  // drawn with fewer triangles the smaller they appear (a robot 20 pixels wide does not need 20
  // slices per rotor); what would cover less than a quarter of a pixel is not drawn at all
  for (auto& list : g.instances) list.clear();
  for (int b = 0; b < Gl::kBatches; ++b) {
    g.batch_vertices[b].clear();
    g.batch_indices[b].clear();
  }
  const double pixels_per_unit = view.height / (2.0 * ty);  // at distance 1
  const double side_x = std::sqrt(1 + tx * tx), side_y = std::sqrt(1 + ty * ty);
  constexpr double kMinPixels = 0.25, kLowFrom = 3.0, kMidFrom = 8.0, kFullFrom = 24.0;
  // the level of detail of a primitive of bounding radius r at `position` (-1: not drawn), and
  // how many pixels a metre there covers
  struct Detail {
    int level;
    double pixels_per_metre;
  };
  auto detail = [&](const Vec3& position, double r) -> Detail {
    const Vec3 rel = position - eye;
    const double d = forward.dot(rel);
    if (d + r < n || d - r > f) return {-1, 0};
    if (std::abs(right.dot(rel)) - d * tx > r * side_x || std::abs(up.dot(rel)) - d * ty > r * side_y) return {-1, 0};
    const double scale = pixels_per_unit / std::max(d, n);
    const double pixels = r * scale;
    if (pixels < kMinPixels) return {-1, scale};
    return {pixels >= kFullFrom ? 0 : pixels >= kMidFrom ? 1 : pixels >= kLowFrom ? 2 : 3, scale};
  };
  // a primitive that appears small: its mesh placed in the world and lit per vertex as the
  // per-pixel shader would light it, with the direction to the eye from the primitive's centre (a
  // face seen from behind is turned towards the eye)
  const Eigen::Vector3f eye_f = eye.cast<float>(), sun_f = kSun.cast<float>();
  auto batchArrays = [&](const std::vector<Vertex>& mesh_vertices, const std::vector<unsigned>& mesh_indices,
                         bool two_sided, const Pose& pose, const Vec3& scale, const RenderNodeSpec& spec) {
    const Eigen::Matrix3f rot = pose.orientation.toRotationMatrix().cast<float>();
    const Eigen::Vector3f at = pose.position.cast<float>(), s = scale.cwiseMax(1e-6).cast<float>();
    const Eigen::Matrix3f place = rot * s.asDiagonal(), turn = rot * s.cwiseInverse().asDiagonal();
    const Eigen::Vector3f to_eye = (eye_f - at).normalized();
    // a flat mesh's faces all lie in the plane through `at` with normal rot z
    const float side = two_sided && rot.col(2).dot(to_eye) < 0 ? -1.0f : 1.0f;
    const auto unit = [](float c) { return static_cast<std::uint8_t>(std::clamp(c, 0.0f, 1.0f) * 255.0f + 0.5f); };
    auto& vertices = g.batch_vertices[two_sided ? 1 : 0];
    auto& indices = g.batch_indices[two_sided ? 1 : 0];
    const auto base = static_cast<unsigned>(vertices.size());
    vertices.resize(base + mesh_vertices.size());
    BatchVertex* out = vertices.data() + base;
    const float* lit_normal = nullptr;  // the mesh normal `color` was computed for (faces share one)
    std::uint8_t color[4] = {0, 0, 0, unit(spec.color[3])};
    for (const Vertex& v : mesh_vertices) {
      const Eigen::Vector3f p = place * Eigen::Map<const Eigen::Vector3f>(v.position) + at;
      if (lit_normal == nullptr || !std::equal(v.normal, v.normal + 3, lit_normal)) {
        const Eigen::Vector3f normal = (side * (turn * Eigen::Map<const Eigen::Vector3f>(v.normal))).normalized();
        const float light = std::min(
            0.3f + 0.45f * std::max(normal.dot(sun_f), 0.0f) + 0.3f * std::max(normal.dot(to_eye), 0.0f), 1.0f);
        for (std::size_t k = 0; k < 3; ++k) color[k] = unit(spec.color[k] * light);
        lit_normal = v.normal;
      }
      out->position[0] = p.x();
      out->position[1] = p.y();
      out->position[2] = p.z();
      std::copy(color, color + 4, out->color);
      ++out;
    }
    const std::size_t first = indices.size();
    indices.resize(first + mesh_indices.size());
    std::transform(mesh_indices.begin(), mesh_indices.end(), indices.begin() + static_cast<std::ptrdiff_t>(first),
                   [base](unsigned k) { return base + k; });
  };
  auto batch = [&](Mesh mesh, const Pose& pose, const Vec3& scale, const RenderNodeSpec& spec) {
    batchArrays(g.mesh_vertices[mesh], g.mesh_indices[mesh], twoSided(mesh), pose, scale, spec);
  };
  // a scene's mesh: always placed and lit here (its vertices are its own, not a unit mesh's)
  auto userMesh = [&](const Pose& pose, const RenderNodeSpec& spec) {
    auto [it, fresh] = g.user_meshes.try_emplace(spec.mesh);
    Gl::UserMesh& m = it->second;
    if (fresh) flatMesh(*spec.mesh, m.vertices, m.indices);
    const Vec3 centre = 0.5 * (spec.mesh->min + spec.mesh->max);
    if (detail(pose.transformPoint(centre), 0.5 * (spec.mesh->max - spec.mesh->min).norm()).level < 0) return;
    batchArrays(m.vertices, m.indices, false, pose, Vec3::Ones(), spec);
  };
  // at full detail: one instance, lit per pixel
  auto add = [&](Mesh mesh, const Pose& pose, const Vec3& scale, const RenderNodeSpec& spec) {
    Instance in;
    for (int k = 0; k < 3; ++k) {
      in.position[k] = static_cast<float>(pose.position[k]);
      in.scale[k] = static_cast<float>(std::max(scale[k], 1e-6));
    }
    const Quat& q = pose.orientation;
    in.rotation[0] = static_cast<float>(q.x());
    in.rotation[1] = static_cast<float>(q.y());
    in.rotation[2] = static_cast<float>(q.z());
    in.rotation[3] = static_cast<float>(q.w());
    for (int k = 0; k < 4; ++k) in.color[k] = spec.color[static_cast<std::size_t>(k)];
    in.grid = spec.grid ? 1.0f : 0.0f;
    g.instances[mesh].push_back(in);
  };
  // at its level of detail (> 0: appears small)
  auto draw = [&](int level, Mesh mesh, const Pose& pose, const Vec3& scale, const RenderNodeSpec& spec) {
    if (level > 0 && !spec.grid)
      batch(mesh, pose, scale, spec);
    else
      add(mesh, pose, scale, spec);
  };
  auto sphere = [&](const Pose& pose, double radius, const RenderNodeSpec& spec) {
    const int level = detail(pose.position, radius).level;
    if (level >= 0) draw(level, static_cast<Mesh>(kSphere + level), pose, Vec3::Constant(radius), spec);
  };
  using P = RenderNodeSpec::Primitive;
  for (const RenderNode& node : nodes) {
    const RenderNodeSpec& s = *node.spec;
    switch (s.primitive) {
      case P::None: break;
      case P::Box: {
        const auto [level, scale] = detail(node.world.position, s.size.norm() / 2);
        if (level < 0) break;
        // a box thinner than a pixel is drawn as its largest face
        Eigen::Index thin;
        const double smallest = s.size.minCoeff(&thin);
        if (level > 0 && smallest * scale < 1.0) {
          // the face: the plane mesh (xy) turned so that its normal is the thin axis
          const Quat turn = thin == 2 ? Quat::Identity()
                                      : Quat(Eigen::AngleAxisd(std::numbers::pi / 2, thin == 0 ? Vec3::UnitY() : Vec3::UnitX()));
          const Vec3 face = turn.conjugate() * s.size;
          draw(level, kPlane, node.world * Pose{Vec3::Zero(), turn}, Vec3(std::abs(face.x()), std::abs(face.y()), 1.0), s);
        } else {
          draw(level, kBox, node.world, s.size, s);
        }
        break;
      }
      case P::Sphere: sphere(node.world, s.radius, s); break;
      case P::Cylinder:
      case P::Capsule: {
        const auto [level, scale] = detail(node.world.position, std::hypot(s.radius, s.length / 2));
        // a cylinder thinner than a pixel (a rotor disc, seen from afar) is drawn as its one face
        if (level > 0 && s.primitive == P::Cylinder && s.length * scale < 1.0)
          draw(level, static_cast<Mesh>(kDisc + level), node.world, Vec3(s.radius, s.radius, 1.0), s);
        else if (level >= 0)
          draw(level, static_cast<Mesh>(kCylinder + level), node.world, Vec3(s.radius, s.radius, s.length), s);
        if (s.primitive == P::Capsule)
          for (double end : {-0.5, 0.5})
            sphere(node.world * Pose{Vec3(0, 0, end * s.length), Quat::Identity()}, s.radius, s);
        break;
      }
      case P::Plane: add(kPlane, node.world, Vec3(s.size.x(), s.size.y(), 1.0), s); break;
      case P::Mesh:
        if (s.mesh != nullptr) userMesh(node.world, s);
        break;
    }
  }
  // shadows: the ground is the first plane facing up; a robot's nodes (they come artifact by
  // artifact) give its footprint, a box around them in x and y; its shadow is a disc of the
  // box's larger half-width at the box's centre, on the ground, darker the nearer the robot is
  if (view.shadows) {
    const RenderNode* ground = nullptr;
    for (const RenderNode& node : nodes)
      if (node.spec->primitive == P::Plane && (node.world.orientation * Vec3::UnitZ()).z() > 0.99) {
        ground = &node;
        break;
      }
    auto& vertices = g.batch_vertices[Gl::kShadowBatch];
    auto& indices = g.batch_indices[Gl::kShadowBatch];
    auto footprint = [](const RenderNodeSpec& s) {
      switch (s.primitive) {
        case P::Box: return 0.5 * std::hypot(s.size.x(), s.size.y());
        case P::Sphere:
        case P::Cylinder:
        case P::Capsule: return s.radius;
        case P::Mesh: return s.mesh != nullptr ? 0.5 * std::hypot(s.mesh->max.x() - s.mesh->min.x(), s.mesh->max.y() - s.mesh->min.y()) : -1.0;
        default: return -1.0;  // casts none
      }
    };
    auto shadow = [&](const Eigen::AlignedBox2d& box, double bottom) {
      const double ground_z = ground->world.position.z(), height = bottom - ground_z;
      if (box.isEmpty() || height < -0.05) return;  // nothing drawn, or below the ground
      const Vec3 centre(box.center().x(), box.center().y(), ground_z);
      const double radius = 0.5 * box.sizes().maxCoeff();
      const int level = detail(centre, radius).level;
      if (level < 0) return;
      const auto alpha = static_cast<std::uint8_t>(std::lround(255 * 0.45 / (1 + 0.15 * std::max(height, 0.0))));
      const std::vector<Vertex>& disc = g.mesh_vertices[kDisc + level];
      const auto base = static_cast<unsigned>(vertices.size());
      for (const Vertex& v : disc)
        vertices.push_back({{static_cast<float>(centre.x() + radius * v.position[0]),
                             static_cast<float>(centre.y() + radius * v.position[1]), static_cast<float>(ground_z)},
                            {0, 0, 0, alpha}});
      for (unsigned k : g.mesh_indices[kDisc + level]) indices.push_back(base + k);
    };
    if (ground != nullptr) {
      const Artifact* owner = nullptr;
      Eigen::AlignedBox2d box;
      double bottom = 0;
      for (const RenderNode& node : nodes) {
        if (node.artifact != owner) {
          if (owner != nullptr) shadow(box, bottom);
          owner = node.artifact;
          box.setEmpty();
          bottom = std::numeric_limits<double>::infinity();
          // only robots: artifacts with a dynamic body
          if (owner != nullptr && (owner->rootCount() == 0 || owner->root().isStatic())) owner = nullptr;
          if (owner == nullptr) continue;
        }
        if (owner == nullptr) continue;
        const double r = footprint(*node.spec);
        if (r < 0) continue;
        const Eigen::Vector2d at = node.world.position.head<2>();
        box.extend(at - Eigen::Vector2d::Constant(r));
        box.extend(at + Eigen::Vector2d::Constant(r));
        bottom = std::min(bottom, node.world.position.z());
      }
      if (owner != nullptr) shadow(box, bottom);
    }
  }

  glViewport(0, 0, view.width, view.height);
  glClearColor(background[0], background[1], background[2], background[3]);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  // first what appears small: the batches, one call each
  auto drawBatch = [&](int b) {
    const auto& vertices = g.batch_vertices[b];
    const auto& indices = g.batch_indices[b];
    if (indices.empty()) return;
    glUseProgram(g.batch_program);
    glUniformMatrix4fv(g.batch_view_projection, 1, GL_FALSE, vp.data());
    glBindVertexArray(g.batch_vao[b]);
    glBindBuffer(GL_ARRAY_BUFFER, g.batch_vertex_buffer[b]);
    const std::size_t vertex_bytes = vertices.size() * sizeof(BatchVertex), index_bytes = indices.size() * sizeof(unsigned);
    if (vertex_bytes > g.batch_vertex_capacity[b]) {
      g.batch_vertex_capacity[b] = std::max(vertex_bytes, 2 * g.batch_vertex_capacity[b]);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(g.batch_vertex_capacity[b]), nullptr, GL_DYNAMIC_DRAW);
    }
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(vertex_bytes), vertices.data());
    if (index_bytes > g.batch_index_capacity[b]) {
      g.batch_index_capacity[b] = std::max(index_bytes, 2 * g.batch_index_capacity[b]);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(g.batch_index_capacity[b]), nullptr, GL_DYNAMIC_DRAW);
    }
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(index_bytes), indices.data());
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(indices.size()), GL_UNSIGNED_INT, nullptr);
  };
  drawBatch(0);
  glDisable(GL_CULL_FACE);
  drawBatch(1);
  glEnable(GL_CULL_FACE);
  // then what appears large, instanced, one call per mesh (the ground last: what stands on it hides
  // part of it, and llvmpipe shades no pixel that fails the depth test)
  for (int f = 0; f < 2; ++f) {
    glUseProgram(g.program[f]);
    glUniformMatrix4fv(g.u_view_projection[f], 1, GL_FALSE, vp.data());
    glUniform3f(g.u_sun[f], static_cast<float>(kSun.x()), static_cast<float>(kSun.y()), static_cast<float>(kSun.z()));
    glUniform3f(g.u_eye[f], static_cast<float>(eye.x()), static_cast<float>(eye.y()), static_cast<float>(eye.z()));
  }
  for (int m = 0; m < kMeshCount; ++m) {
    const auto& list = g.instances[m];
    if (list.empty()) continue;
    glUseProgram(g.program[flatFaces(m) ? 1 : 0]);
    // planes and discs are seen from both sides
    if (twoSided(m)) glDisable(GL_CULL_FACE);
    glBindVertexArray(g.vao[m]);
    glBindBuffer(GL_ARRAY_BUFFER, g.instance_buffer[m]);
    // grow the buffer only when needed, else rewrite it in place
    const std::size_t bytes = list.size() * sizeof(Instance);
    if (bytes > g.instance_capacity[m]) {
      g.instance_capacity[m] = std::max(bytes, 2 * g.instance_capacity[m]);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(g.instance_capacity[m]), nullptr, GL_DYNAMIC_DRAW);
    }
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(bytes), list.data());
    glDrawElementsInstanced(GL_TRIANGLES, g.index_count[m], GL_UNSIGNED_INT, nullptr, static_cast<GLsizei>(list.size()));
    if (twoSided(m)) glEnable(GL_CULL_FACE);
  }
  // the shadows, over the ground: blended, pulled towards the eye so that they win against the
  // ground they lie on, without writing depth (so they never hide each other)
  if (!g.batch_indices[Gl::kShadowBatch].empty()) {
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDepthMask(GL_FALSE);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(-2.0f, -4.0f);
    drawBatch(Gl::kShadowBatch);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glEnable(GL_CULL_FACE);
  }
  glBindVertexArray(0);
  if (view.depth) {
    g.depth.resize(static_cast<std::size_t>(view.width) * view.height);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, view.width, view.height, GL_DEPTH_COMPONENT, GL_FLOAT, g.depth.data());
  }
  // the colour reaches our buffer on glFinish (Mesa copies it out then), not on a depth read
  glFinish();
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    throw Error("osmesa renderer: OpenGL error " + std::to_string(e) + " while drawing");

  // the buffer's first row is the bottom one; images are top row first
  out.width = view.width;
  out.height = view.height;
  out.rgb.resize(static_cast<std::size_t>(view.width) * view.height * 3);
  for (int y = 0; y < view.height; ++y) {
    const std::uint8_t* src = g.buffer.data() + static_cast<std::size_t>(view.height - 1 - y) * view.width * 4;
    std::uint8_t* dst = out.rgb.data() + static_cast<std::size_t>(y) * view.width * 3;
    for (int x = 0; x < view.width; ++x, src += 4, dst += 3) {
      dst[0] = src[0];
      dst[1] = src[1];
      dst[2] = src[2];
    }
  }
  if (view.depth) {
    // window depth to distance along the optical axis
    out.depth.resize(g.depth.size());
    for (int y = 0; y < view.height; ++y)
      for (int x = 0; x < view.width; ++x) {
        const double d = g.depth[static_cast<std::size_t>(view.height - 1 - y) * view.width + x];
        out.depth[static_cast<std::size_t>(y) * view.width + x] =
            d >= 1.0 ? std::numeric_limits<float>::infinity()
                     : static_cast<float>(2 * n * f / (f + n - (2 * d - 1) * (f - n)));
      }
  } else {
    out.depth.clear();
  }
}

}  // namespace ssx::detail
