// Free bodies stepped by ssx (OdeSettings::integrate_free_bodies) against ODE's own QuickStep: the
// same bits in every step, for bodies flying free, kinematic ones, and bodies that land on the
// ground and hit each other (handed to ODE while they touch, back to ssx once they part).
#include "base/worker_pool.hpp"
#include "scene_util.hpp"

#include <ssx/physic_engine.hpp>
#include <ssx/ssx.hpp>
#include <ssx/state.hpp>

#include <catch2/catch.hpp>

#include <cstring>
#include <memory>
#include <random>
#include <vector>

using namespace ssx;

namespace {

constexpr int kBodies = 150;  // over two home worlds (blocks of 64)

std::vector<std::byte> saved(const PhysicEngine& e) {
  std::vector<std::byte> out;
  StateWriter w(out);
  e.saveState(w);
  return out;
}

// bodies of many shapes and inertias (products of inertia too), thrown upwards and spinning over
// the ground; a few kinematic ones gliding; some close enough to meet in the air
std::unique_ptr<PhysicEngine> scene(bool integrate_free, int partitions, int substeps) {
  PhysicsSettings s;
  s.gravity = Vec3(0.3, -0.2, -9.81);
  s.substeps = substeps;
  s.ode.partitions = partitions;
  s.ode.integrate_free_bodies = integrate_free;
  auto e = createPhysicEngine(s);
  e->addStatic({Shape::plane()}, Pose{});
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < kBodies; ++i) {
    MassProperties m;
    m.mass = 0.03 + 0.5 * (1.0 + u(rng));
    Mat3 a;
    for (int k = 0; k < 9; ++k) a(k / 3, k % 3) = 0.3 * u(rng);
    m.inertia = (a * a.transpose() + Mat3::Identity() * 0.01) * m.mass * 0.1;  // symmetric, positive definite
    BodyState state;
    // pairs of bodies side by side (meeting in the air), the rest 1 m apart
    state.pose.position = Vec3((i / 2) * 1.0 + (i % 2) * 0.15, 0.3 * u(rng), 0.4 + 0.3 * (1 + u(rng)));
    state.pose.orientation = Quat(1 + u(rng), u(rng), u(rng), u(rng)).normalized();
    state.linear_velocity = Vec3(i % 2 == 0 ? 0.4 : -0.4, u(rng), 2 * u(rng));
    state.angular_velocity = Vec3(u(rng), u(rng), u(rng)) * 8.0;
    const std::vector<Shape> shapes =
        i % 3 == 0 ? std::vector<Shape>{Shape::sphere(0.05)}
                   : std::vector<Shape>{Shape::box(Vec3(0.1, 0.06, 0.02)),
                                        Shape::sphere(0.02, Pose{Vec3(0.04, 0, 0.01), Quat::Identity()})};
    const int b = e->addBody(m, shapes, state);
    if (i % 17 == 5) e->setKinematic(b);
  }
  return e;
}

// a wrench on every body, changing each step (the same on both engines)
std::vector<Wrench> wrenches(int step) {
  std::vector<Wrench> w(kBodies);
  std::mt19937_64 rng(1000 + static_cast<std::uint64_t>(step));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Wrench& x : w) {
    x.force = Vec3(u(rng), u(rng), u(rng)) * 0.5;
    x.torque = Vec3(u(rng), u(rng), u(rng)) * 0.002;
  }
  return w;
}

}  // namespace

TEST_CASE("free bodies stepped by ssx give the bits of ODE's QuickStep, landing and colliding included",
          "[physics][ode]") {
  for (const int substeps : {1, 2}) {
    INFO(substeps << " substeps");
    auto mine = scene(true, 16, substeps);
    auto ode = scene(false, 16, substeps);
    detail::WorkerPool pool(2);
    mine->setTaskRunner(&pool);
    const Nanoseconds dt = toNanoseconds(0.002);
    std::size_t contacts = 0, steps_with_contacts = 0, free_steps = 0;
    for (int k = 0; k < 1500; ++k) {
      const std::vector<Wrench> w = wrenches(k);
      mine->step(dt, w);
      ode->step(dt, w);
      contacts += ode->contactCount();
      steps_with_contacts += ode->contactCount() > 0 ? 1 : 0;
      free_steps += ode->contactCount() == 0 ? 1 : 0;
      REQUIRE(mine->contactCount() == ode->contactCount());
      if (k % 50 == 0 || k == 1499) REQUIRE(saved(*mine) == saved(*ode));
    }
    // the run had both: steps where every body flew free, and bodies resting and hitting
    CHECK(free_steps > 20);
    CHECK(steps_with_contacts > 500);
    CHECK(contacts > 10000);
    std::vector<BodyState> a(kBodies), b(kBodies);
    mine->readStates(a);
    ode->readStates(b);
    // (some came to rest on the ground)
    int resting = 0;
    for (const BodyState& s : b) resting += s.pose.position.z() < 0.1 ? 1 : 0;
    CHECK(resting > 20);
    for (int i = 0; i < kBodies; ++i)
      CHECK(std::memcmp(a[static_cast<std::size_t>(i)].pose.position.data(),
                        b[static_cast<std::size_t>(i)].pose.position.data(), 3 * sizeof(double)) == 0);
  }
}

TEST_CASE("a free flight stepped by ssx for 10 s is ODE's to the bit, and a restored state goes on the same",
          "[physics][ode]") {
  PhysicsSettings s;
  auto flight = [&](bool integrate_free) {
    s.ode.integrate_free_bodies = integrate_free;
    auto e = createPhysicEngine(s);
    MassProperties m;
    m.mass = 0.033;
    m.inertia << 1.4e-5, 2e-7, 0, 2e-7, 1.4e-5, 0, 0, 0, 2.2e-5;
    BodyState state;
    state.pose.position = Vec3(0, 0, 1000);  // far from everything: no contact in 10 s
    state.angular_velocity = Vec3(3, -2, 20);
    e->addBody(m, {Shape::box(Vec3(0.09, 0.09, 0.03))}, state);
    return e;
  };
  auto mine = flight(true), ode = flight(false);
  std::vector<Wrench> w(1);
  w[0].force = Vec3(0.01, 0, 0.30);
  w[0].torque = Vec3(1e-6, -2e-6, 0);
  const Nanoseconds dt = toNanoseconds(0.002);
  std::vector<std::byte> halfway;
  for (int k = 0; k < 5000; ++k) {
    mine->step(dt, w);
    ode->step(dt, w);
    if (k == 2499) halfway = saved(*mine);
  }
  REQUIRE(saved(*mine) == saved(*ode));
  std::vector<BodyState> end(1);
  mine->readStates(end);
  CHECK(end[0].pose.position.z() < 1000);  // it fell (thrust below its weight)
  // restored halfway, the same end
  auto again = flight(true);
  StateReader r(halfway);
  again->restoreState(r);
  for (int k = 2500; k < 5000; ++k) again->step(dt, w);
  CHECK(saved(*again) == saved(*mine));
}

TEST_CASE("a swarm taking off from the ground and flying has the same bits with free bodies stepped by ssx or by ODE",
          "[physics][ode][quadrotor]") {
  // nine Crazyflies (firmware controller, IMU and motion-capture noise) on the ground, 0.3 m
  // apart, climbing to 1 m: resting contacts, then free flight; with free bodies stepped by ssx
  // and with every body handed to ODE
  auto scene = [](bool integrate_free, int threads) {
    SceneOptions options;
    options.threads = threads;
    return loadSceneFromString(
        std::string("<scene><environment timestep=\"0.002\" seed=\"3\"/>"
                    "<physics engine=\"ode\" integrate_free_bodies=\"") +
            (integrate_free ? "true" : "false") + "\"/><type name=\"cf\" file=\"" +
            (ssx::test::kArtifacts / "crazyflie.xml").string() +
            "\"/><ground/><swarm type=\"cf\" count=\"9\" name=\"cf{i}\" spacing=\"0.3\" xyz=\"0 0 0.0105\">"
            "<driver offset=\"0 0 1\"/></swarm></scene>",
        "cf.xml", ssx::test::kArtifacts, options);
  };
  Scene mine = scene(true, 2), ode = scene(false, 1);
  std::size_t contacts = 0;
  for (int k = 0; k < 1000; ++k) {
    mine.environment->step();
    ode.environment->step();
    contacts += ode.environment->physics().contactCount();
    REQUIRE(mine.environment->stateHash() == ode.environment->stateHash());
  }
  CHECK(contacts > 0);  // they stood on the ground first
  CHECK(mine.environment->saveState() == ode.environment->saveState());
  // and they flew: every one above 0.5 m after 2 s
  int flying = 0;
  for (std::size_t a = 0; a < mine.environment->artifactCount(); ++a) {
    const PhysicNode& root = mine.environment->artifact(a).root();
    if (root.isStatic()) continue;  // (the ground)
    CHECK(root.state().pose.position.z() > 0.5);
    ++flying;
  }
  CHECK(flying == 9);
}
