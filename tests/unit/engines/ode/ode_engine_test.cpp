// The ODE engine's partitions: bodies spread over several worlds stepped in parallel behave as in
// one world, touch across partitions, and give the same bits on any number of threads and after
// a save and restore.
#include "base/worker_pool.hpp"

#include <ssx/physic_engine.hpp>
#include <ssx/state.hpp>

#include <catch2/catch.hpp>

#include <cstring>
#include <memory>
#include <vector>

using namespace ssx;

namespace {

MassProperties ballMass() {
  MassProperties m;
  m.mass = 1.0;
  m.inertia = Mat3::Identity() * 0.004;
  return m;
}

BodyState at(const Vec3& p, const Vec3& v = Vec3::Zero(), const Vec3& w = Vec3::Zero()) {
  BodyState s;
  s.pose.position = p;
  s.linear_velocity = v;
  s.angular_velocity = w;
  return s;
}

bool sameBits(const std::vector<BodyState>& a, const std::vector<BodyState>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const BodyState &x = a[i], &y = b[i];
    if (std::memcmp(x.pose.position.data(), y.pose.position.data(), 3 * sizeof(double)) != 0 ||
        std::memcmp(x.pose.orientation.coeffs().data(), y.pose.orientation.coeffs().data(), 4 * sizeof(double)) != 0 ||
        std::memcmp(x.linear_velocity.data(), y.linear_velocity.data(), 3 * sizeof(double)) != 0 ||
        std::memcmp(x.angular_velocity.data(), y.angular_velocity.data(), 3 * sizeof(double)) != 0)
      return false;
  }
  return true;
}

std::vector<BodyState> states(const PhysicEngine& e) {
  std::vector<BodyState> out(e.bodyCount());
  e.readStates(out);
  return out;
}

// the ODE engine deals bodies to home worlds in blocks of 64
constexpr int kBlock = 64;
constexpr int kBodies = 3 * kBlock + 5;  // enough for several home worlds
constexpr int kA = 0;
constexpr int kB = kBlock;  // the first body of the next home world

// two balls on a head-on course, one from each of two home worlds; every other ball drifts alone,
// far away, spinning (free bodies: no contact, no constraint)
std::unique_ptr<PhysicEngine> headOn(int partitions) {
  PhysicsSettings s;
  s.gravity = Vec3::Zero();
  s.restitution = 0.5;
  s.ode.partitions = partitions;
  auto e = createPhysicEngine(s);
  for (int i = 0; i < kBodies; ++i) {
    BodyState state = at(Vec3(0, 10.0 * i, 0), Vec3(0.01 * (i % 7), 0, 0.02), Vec3(0.1, 0.3 * (i % 3), -0.2));
    if (i == kA) state = at(Vec3(-0.3, 0, 0), Vec3(1, 0, 0));
    if (i == kB) state = at(Vec3(0.3, 0.05, 0), Vec3(-1, 0, 0), Vec3(0, 0, 1));  // off-centre, spinning
    e->addBody(ballMass(), {Shape::sphere(0.1)}, state);
  }
  return e;
}

}  // namespace

TEST_CASE("bodies in different partitions collide as in one world, on any number of threads", "[physics][parallel]") {
  const std::vector<Wrench> none(kBodies);
  const Nanoseconds dt = toNanoseconds(0.005);

  // one world, one thread: the reference
  auto one = headOn(1);
  std::vector<std::vector<BodyState>> reference;
  std::size_t contacts = 0;
  for (int k = 0; k < 120; ++k) {
    one->step(dt, none);
    contacts += one->contactCount();
    reference.push_back(states(*one));
  }
  // they met and bounced apart
  REQUIRE(contacts > 0);
  CHECK(reference.back()[kA].linear_velocity.x() < 0);
  CHECK(reference.back()[kB].linear_velocity.x() > 0);

  for (unsigned threads : {1u, 2u, 4u}) {
    INFO(threads << " threads");
    detail::WorkerPool pool(threads);
    auto split = headOn(16);
    split->setTaskRunner(&pool);
    std::size_t split_contacts = 0;
    for (int k = 0; k < 120; ++k) {
      split->step(dt, none);
      split_contacts += split->contactCount();
      REQUIRE(sameBits(states(*split), reference[static_cast<std::size_t>(k)]));
    }
    CHECK(split_contacts == contacts);
  }
}

TEST_CASE("a pile of boxes on the ground by an obstacle: same bits on 1, 2 and 4 threads and after a restore, on either engine",
          "[physics][parallel]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  // boxes dropped in touching columns onto the ground next to a static wall: contact groups that
  // span home worlds, resting contacts with the ground in every world
  auto build = [&] {
    PhysicsSettings s;
    s.engine = engine;
    auto e = createPhysicEngine(s);
    e->addStatic({Shape::plane()}, Pose{});
    e->addStatic({Shape::box(Vec3(0.2, 4, 1))}, Pose{Vec3(-0.35, 0, 0.5), Quat::Identity()});
    MassProperties m;
    m.mass = 0.5;
    m.inertia = Mat3::Identity() * 0.002;
    for (int i = 0; i < 200; ++i) {
      const int column = i % 20, level = i / 20;
      const Quat tilt(Eigen::AngleAxisd(0.05 * (i % 5), Vec3::UnitZ()));
      BodyState st = at(Vec3(0.21 * (column % 4), 0.21 * (column / 4), 0.11 + 0.205 * level));
      st.pose.orientation = tilt;
      e->addBody(m, {Shape::box(Vec3(0.2, 0.2, 0.2))}, st);
    }
    return e;
  };
  const Nanoseconds dt = toNanoseconds(0.005);
  std::vector<Wrench> push(200);
  for (int i = 0; i < 200; i += 7) push[static_cast<std::size_t>(i)].force = Vec3(-2.0, 0.5, 0);  // into the wall

  std::vector<BodyState> reference;
  std::vector<std::byte> saved;
  std::size_t contacts = 0;
  for (unsigned threads : {1u, 2u, 4u}) {
    INFO(threads << " threads");
    detail::WorkerPool pool(threads);
    auto e = build();
    e->setTaskRunner(&pool);
    for (int k = 0; k < 300; ++k) {
      e->step(dt, push);
      contacts += e->contactCount();
      if (k == 149 && threads == 1) {
        StateWriter w(saved);
        e->saveState(w);
      }
    }
    if (threads == 1)
      reference = states(*e);
    else
      CHECK(sameBits(states(*e), reference));
  }
  REQUIRE(contacts > 0);
  // restored half way into a freshly built world, on two threads, it ends with the same bits
  detail::WorkerPool pool(2);
  auto restored = build();
  restored->setTaskRunner(&pool);
  StateReader r(saved);
  restored->restoreState(r);
  for (int k = 150; k < 300; ++k) restored->step(dt, push);
  CHECK(sameBits(states(*restored), reference));
}
