// Mesh shapes on the engines (ode_meshes.cpp, and Bullet's alike): a moving body's mesh collides as
// its convex hull (a tetrahedron-made cube rests on the ground at its half height, a cone of
// vertices rests on its base), a static mesh as its triangles (a sphere rests on a triangle floor);
// a hull lying beside its own frame (a robot link's mesh often does) collides where it is.
#include "engine_util.hpp"

#include <catch2/catch.hpp>
#include <unistd.h>

#include <cstdio>
#include <string>

#include <cmath>
#include <memory>
#include <vector>

using namespace ssx;
using namespace ssx::test;

namespace {

// a cube of edge `a` as twelve triangles (outward), its hull computed
std::shared_ptr<TriangleMesh> cubeMesh(double a) {
  auto m = std::make_shared<TriangleMesh>();
  m->file = "cube";
  for (int i = 0; i < 8; ++i) m->vertices.emplace_back((i & 1 ? 0.5 : -0.5) * a, (i & 2 ? 0.5 : -0.5) * a, (i & 4 ? 0.5 : -0.5) * a);
  const std::uint32_t faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                      {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& f : faces) m->triangles.insert(m->triangles.end(), {f[0], f[1], f[2]});
  m->computeHull();
  return m;
}

// what this process writes to standard output while alive (ODE's convex checks print there)
class StdoutCapture {
 public:
  StdoutCapture() : file_(std::tmpfile()), saved_(dup(1)) {
    std::fflush(stdout);
    dup2(fileno(file_), 1);
  }
  ~StdoutCapture() {
    restore();
    std::fclose(file_);
  }
  std::string text() {
    restore();
    std::string out;
    std::rewind(file_);
    for (int c; (c = std::fgetc(file_)) != EOF;) out += static_cast<char>(c);
    return out;
  }

 private:
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stdout);
    dup2(saved_, 1);
    close(saved_);
    saved_ = -1;
  }
  std::FILE* file_;
  int saved_;
};

// a flat floor of two triangles, 10 m across, at z = 0
std::shared_ptr<TriangleMesh> floorMesh() {
  auto m = std::make_shared<TriangleMesh>();
  m->file = "floor";
  m->vertices = {Vec3(-5, -5, 0), Vec3(5, -5, 0), Vec3(5, 5, 0), Vec3(-5, 5, 0)};
  m->triangles = {0, 1, 2, 0, 2, 3};
  m->min = Vec3(-5, -5, 0);
  m->max = Vec3(5, 5, 0);
  return m;
}

double settledHeight(PhysicEngine& engine, int body) {
  const std::vector<Wrench> none(engine.bodyCount());
  for (int k = 0; k < 1000; ++k) engine.step(toNanoseconds(0.002), none);
  return states(engine)[static_cast<std::size_t>(body)].pose.position.z();
}

}  // namespace

TEST_CASE("mesh shapes: a moving mesh collides as its hull, a static one as its triangles", "[physics][ode][bullet][mesh]") {
  for (const std::string name : {"ode", "bullet"}) {
    CAPTURE(name);
    SECTION("a cube mesh dropped on the ground rests on a face " + name) {
      auto engine = makeEngine(name);
      engine->addStatic({Shape::plane()}, Pose{});
      PhysicNodeSpec spec;
      spec.shapes.push_back(Shape::fromMesh(cubeMesh(0.2)));
      spec.mass = 1.0;
      BodyState s;
      s.pose.position = Vec3(0, 0, 0.3);
      const int body = engine->addBody(combinedMass(spec), spec.shapes, s);
      // (the hull's margin and the contacts' softness: within 2 mm)
      CHECK(settledHeight(*engine, body) == Approx(0.1).margin(0.002));
    }
    SECTION("a sphere on a static triangle floor rests on it " + name) {
      auto engine = makeEngine(name);
      engine->addStatic({Shape::fromMesh(floorMesh())}, Pose{});
      const int ball = [&] {
        PhysicNodeSpec spec;
        spec.shapes.push_back(Shape::sphere(0.1));
        spec.mass = 1.0;
        BodyState s;
        s.pose.position = Vec3(0.3, -0.2, 0.5);
        return engine->addBody(combinedMass(spec), spec.shapes, s);
      }();
      CHECK(settledHeight(*engine, ball) == Approx(0.1).margin(0.002));
    }
  }
}

TEST_CASE("mesh shapes: a hull whose vertices lie beside its frame collides where it is, ODE not warning of it", "[physics][ode][bullet][mesh]") {
  // the cube's vertices 0.5 m along x of the mesh's frame, the shape put back by -0.5 m: the frame's
  // origin is outside the hull, as for most links of the KUKA iiwa's meshes
  auto beside = cubeMesh(0.2);
  for (Vec3& v : beside->vertices) v.x() += 0.5;
  beside->computeHull();
  for (const std::string name : {"ode", "bullet"}) {
    CAPTURE(name);
    StdoutCapture out;
    auto engine = makeEngine(name);
    engine->addStatic({Shape::box(Vec3(2, 2, 0.4), Pose{Vec3(0, 0, -0.2), Quat::Identity()})}, Pose{});
    PhysicNodeSpec spec;
    spec.shapes.push_back(Shape::fromMesh(beside, Pose{Vec3(-0.5, 0, 0), Quat::Identity()}));
    spec.mass = 1.0;
    BodyState s;
    s.pose.position = Vec3(0.1, 0, 0.3);
    s.pose.orientation = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitY()));
    const int body = engine->addBody(combinedMass(spec), spec.shapes, s);
    const double height = settledHeight(*engine, body);
    const std::string printed = out.text();
    // tipped onto a face of the box below, it rests at half its edge, near where it fell
    CHECK(height == Approx(0.1).margin(0.002));
    CHECK(std::abs(states(*engine)[0].pose.position.x() - 0.1) < 0.1);
    CHECK(printed.find("WARNING") == std::string::npos);
  }
}

TEST_CASE("mesh shapes: a mesh body weighs as its hull at its density", "[physics][mesh]") {
  PhysicNodeSpec spec;
  Shape s = Shape::fromMesh(cubeMesh(0.2), Pose{Vec3(0, 0, 1), Quat::Identity()});
  s.density = 500;
  spec.shapes.push_back(s);
  const MassProperties m = combinedMass(spec);
  CHECK(m.mass == Approx(0.2 * 0.2 * 0.2 * 500));
  CHECK(m.center_of_mass.isApprox(Vec3(0, 0, 1)));
  CHECK(m.inertia(0, 0) == Approx(m.mass * (0.04 + 0.04) / 12));
  CHECK(std::abs(m.inertia(0, 1)) < 1e-15);
}
