// The same scenes on both physics engines (ODE and Bullet), against closed forms and each other:
// every rigid-body check of the physics (spec section 7, no rotors) runs on both.
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <numbers>

using namespace ssx;
using ssx::test::at;

namespace {

const std::filesystem::path kArtifacts = std::filesystem::path(SSX_EXAMPLES_DIR) / "artifacts";
const std::filesystem::path kScenes = std::filesystem::path(SSX_EXAMPLES_DIR) / "scenes";

EnvironmentSettings settings(const std::string& engine, double dt, bool gravity = true) {
  EnvironmentSettings s;
  s.timestep = toNanoseconds(dt);
  s.threads = 1;
  s.physics.engine = engine;
  if (!gravity) s.physics.gravity = Vec3::Zero();
  return s;
}

Vec3 bodyRate(const Artifact& a) {
  const BodyState s = a.state();
  return s.pose.orientation.conjugate() * s.angular_velocity;
}

}  // namespace

TEST_CASE("cross_engine: free fall and a projectile follow the closed form of semi-implicit Euler", "[physics][cross_engine]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  // both engines integrate v += g h, then x += v h: after n steps z = z0 + v0 t - g h^2 n (n + 1) / 2,
  // the exact parabola plus an O(h) offset of -g t h / 2
  const double h = 0.001, g = 9.81;
  Environment env(settings(engine, h));
  Artifact& drop = env.addArtifact("drop", at(0, 0, 100));
  drop.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
  Artifact& thrown = env.addArtifact("thrown", at(5, 0, 100));
  thrown.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
  thrown.root().setVelocity(Vec3(3, -1, 4), Vec3::Zero());
  const int n = 1000;
  env.step(n);
  const double t = n * h;
  const double offset = g * h * h * n * (n + 1) / 2.0;
  CHECK(drop.pose().position.z() == Approx(100.0 - offset).margin(1e-9));
  CHECK(drop.state().linear_velocity.z() == Approx(-g * t).margin(1e-9));
  CHECK(std::abs(drop.pose().position.z() - (100.0 - 0.5 * g * t * t)) == Approx(0.5 * g * t * h).margin(1e-9));
  CHECK(drop.state().linear_acceleration.isApprox(Vec3(0, 0, -g), 1e-9));
  const Vec3 p = thrown.pose().position;
  CHECK(p.x() == Approx(5.0 + 3.0 * t).margin(1e-9));
  CHECK(p.y() == Approx(-1.0 * t).margin(1e-9));
  CHECK(p.z() == Approx(100.0 + 4.0 * t - offset).margin(1e-9));
  CHECK(thrown.state().linear_velocity.isApprox(Vec3(3, -1, 4 - g * t), 1e-9));
}

TEST_CASE("cross_engine: a torque-free top precesses at (J3 - J1)/J1 w3, keeping its energy and momentum",
          "[physics][cross_engine]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  Environment env(settings(engine, 0.001, false));
  const Vec3 j(0.009, 0.009, 0.018);
  const Mat3 inertia = j.asDiagonal();
  Artifact& a = env.addArtifact("top", at(0, 0, 0));
  a.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0, &inertia));
  a.root().setVelocity(Vec3::Zero(), Vec3(0.5, 0, 10));
  env.start();
  const double e0 = 0.5 * bodyRate(a).dot(j.cwiseProduct(bodyRate(a)));
  const Vec3 l0 = a.state().pose.orientation * j.cwiseProduct(bodyRate(a));
  double angle = 0, last = std::atan2(bodyRate(a).y(), bodyRate(a).x());
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    env.step();
    const Vec3 w = bodyRate(a);
    const double now = std::atan2(w.y(), w.x());
    double d = now - last;
    if (d > std::numbers::pi) d -= 2 * std::numbers::pi;
    if (d < -std::numbers::pi) d += 2 * std::numbers::pi;
    angle += d;
    last = now;
  }
  CHECK(angle / (n * 0.001) == Approx(10.0).epsilon(0.01));
  const Vec3 w = bodyRate(a);
  const double e = 0.5 * w.dot(j.cwiseProduct(w));
  const Vec3 l = a.state().pose.orientation * j.cwiseProduct(w);
  const double energy_drift = (e - e0) / e0, momentum_drift = (l - l0).norm() / l0.norm();
  INFO("energy drift " << energy_drift << ", momentum drift " << momentum_drift);
  CHECK(std::abs(energy_drift) < 1e-3);
  CHECK(momentum_drift < 1e-3);
  // docs/physics.md's figures, to their last digit
  CHECK(energy_drift == Approx(engine == "ode" ? -1.9e-4 : -2.3e-4).margin(0.05e-4));
  CHECK(momentum_drift == Approx(engine == "ode" ? 1.1e-4 : 1.2e-4).margin(0.05e-4));
  WARN(engine << ": torque-free top over 2 s: energy drift " << energy_drift << ", momentum drift " << momentum_drift);
}

TEST_CASE("cross_engine: spin about the intermediate axis flips, and a tilted inertia turns as the same body",
          "[physics][cross_engine]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  // Dzhanibekov: a spin about the intermediate axis reverses
  {
    Environment env(settings(engine, 0.001, false));
    const Mat3 j = Vec3(1e-2, 2e-2, 3e-2).asDiagonal();
    Artifact& a = env.addArtifact("t", at(0, 0, 0));
    a.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0, &j));
    a.root().setVelocity(Vec3::Zero(), Vec3(0.01, 5.0, 0.01));
    double min_wy = 5.0, first_flip = -1;
    for (int i = 0; i < 10000; ++i) {
      env.step();
      min_wy = std::min(min_wy, bodyRate(a).y());
      if (first_flip < 0 && bodyRate(a).y() < 0) first_flip = (i + 1) * 0.001;
    }
    INFO("first flip at " << first_flip << " s");
    CHECK(first_flip == Approx(2.7).margin(0.05));  // docs/physics.md's figure
    CHECK(min_wy < -4.5);
  }
  // the same body described in a frame turned 30 degrees: the inertia is no longer diagonal (Bullet
  // needs principal axes, ODE takes it as it is); the node turns exactly as the diagonal one
  {
    Environment env(settings(engine, 0.001, false));
    const Quat turn(Eigen::AngleAxisd(std::numbers::pi / 6, Vec3(1, 1, 0).normalized()));
    const Mat3 diagonal = Vec3(1e-2, 2e-2, 3e-2).asDiagonal();
    const Mat3 tilted = turn.toRotationMatrix() * diagonal * turn.toRotationMatrix().transpose();
    Artifact& plain = env.addArtifact("plain", at(0, 0, 0));
    plain.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0, &diagonal));
    plain.root().setVelocity(Vec3::Zero(), Vec3(0.3, 0.2, 5.0));  // about the major axis: stable
    // the tilted description: its node frame is `turn` away from the principal one
    Artifact& other = env.addArtifact("tilted", Pose{Vec3(1, 0, 0), turn.conjugate()});
    other.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0, &tilted));
    other.root().setVelocity(Vec3::Zero(), Vec3(0.3, 0.2, 5.0));
    env.step(3000);
    const Quat qa = plain.pose().orientation;
    const Quat qb = other.pose().orientation * turn;  // back to the principal frame
    INFO("orientations differ by " << qa.angularDistance(qb) << " rad");
    CHECK(qa.angularDistance(qb) < 1e-6);
    CHECK((plain.state().angular_velocity - other.state().angular_velocity).norm() < 1e-6);
  }
}

TEST_CASE("cross_engine: a box resting on the ground stays put", "[physics][cross_engine]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  Environment env(settings(engine, 0.001));
  env.addGround();
  Artifact& box = env.addArtifact("box", at(0.3, -0.2, 0.1));
  box.addPhysicRoot(test::boxBody(Vec3(0.2, 0.2, 0.2), 1.0));
  env.step(5000);
  const Pose p = box.pose();
  INFO("at " << p.position.transpose());
  CHECK((p.position.head<2>() - Vec3(0.3, -0.2, 0).head<2>()).norm() < 1e-4);
  CHECK(p.position.z() == Approx(0.1).margin(2e-3));
  CHECK(p.orientation.angularDistance(Quat::Identity()) < 1e-3);
  CHECK(box.state().linear_velocity.norm() < 1e-3);
  CHECK(env.physics().contactCount() >= 3);  // it stands on more than one point
}

TEST_CASE("cross_engine: a box sliding on the ground decelerates at mu g and stops", "[physics][cross_engine]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  const double mu = 0.5, g = 9.81, v0 = 2.0, h = 0.001;
  EnvironmentSettings s = settings(engine, h);
  s.physics.friction = mu;
  Environment env(s);
  env.addGround();
  Artifact& box = env.addArtifact("box", at(0, 0, 0.1));
  box.addPhysicRoot(test::boxBody(Vec3(0.2, 0.2, 0.2), 1.0));
  env.step(300);  // settled
  box.root().setVelocity(Vec3(v0, 0, 0), Vec3::Zero());
  const double x0 = box.pose().position.x();
  double v_at_50 = 0, v_at_250 = 0, stopped_at = -1;
  for (int k = 1; k <= 1000; ++k) {
    env.step();
    const double v = box.state().linear_velocity.x();
    if (k == 50) v_at_50 = v;
    if (k == 250) v_at_250 = v;
    if (stopped_at < 0 && v < 1e-3) stopped_at = k * h;
  }
  const double deceleration = (v_at_50 - v_at_250) / (200 * h);
  const double distance = box.pose().position.x() - x0;
  INFO("deceleration " << deceleration << " m/s^2, stopped after " << stopped_at << " s and " << distance << " m");
  CHECK(deceleration == Approx(mu * g).epsilon(0.05));
  CHECK(stopped_at == Approx(v0 / (mu * g)).epsilon(0.05));
  CHECK(distance == Approx(v0 * v0 / (2 * mu * g)).epsilon(0.05));
  CHECK(box.pose().orientation.angularDistance(Quat::Identity()) < 0.01);  // it slid, it did not tip
}

TEST_CASE("cross_engine: an mk_quad hovers still and takes off to its hover point", "[quadrotor][cross_engine]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  auto scene = [&](const std::string& artifact) {
    return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"4\"/><physics engine=\"" + engine +
                                   "\"/><type name=\"q\" file=\"mk_quad.xml\"/><ground/>" + artifact + "</scene>",
                               "quad.xml", kArtifacts);
  };
  {
    Scene s = scene(
        "<artifact name=\"quad\" type=\"q\" xyz=\"0 0 1\"><sensor index=\"0\" noise=\"false\"/><sensor index=\"1\" "
        "position_noise=\"0\" velocity_noise=\"0\"/></artifact>");
    Environment& env = *s.environment;
    Artifact& quad = *env.findArtifact("quad");
    env.step(500);
    const Vec3 start = quad.pose().position;
    double worst = 0;
    for (int i = 0; i < 5000; ++i) {
      env.step();
      worst = std::max(worst, (quad.pose().position - start).norm());
    }
    INFO("hover: largest excursion " << worst << " m");
    CHECK(worst < 0.01);
    CHECK((quad.pose().position - Vec3(0, 0, 1)).norm() < 0.01);
  }
  {
    Scene s = scene("<artifact name=\"quad\" type=\"q\" xyz=\"0 0 0.04\"><driver offset=\"0 0 1\"/></artifact>");
    Environment& env = *s.environment;
    std::size_t contacts = 0;
    for (int k = 0; k < 250; ++k) {
      env.step();
      contacts += env.physics().contactCount();
    }
    CHECK(contacts > 0);  // it stood on the ground
    env.step(2250);
    INFO("after take-off at " << env.findArtifact("quad")->pose().position.transpose());
    CHECK((env.findArtifact("quad")->pose().position - Vec3(0, 0, 1.04)).norm() < 0.05);
  }
}

TEST_CASE("cross_engine: the figure-eight tracking errors of the two engines are within 10 % of each other",
          "[quadrotor][cross_engine]") {
  for (const char* kind : {"eight_horizontal", "eight_vertical"}) {
    double mean[2] = {0, 0};
    for (int e = 0; e < 2; ++e) {
      SceneOptions options;
      options.physics_engine = e == 0 ? "ode" : "bullet";
      Scene s = loadScene(kScenes / (std::string(kind) + ".xml"), options);
      Environment& env = *s.environment;
      Artifact& quad = *env.findArtifact("quad");
      env.start();
      auto* tracker = dynamic_cast<SetpointInterface*>(quad.driver());
      REQUIRE(tracker != nullptr);
      double sum = 0;
      int n = 0;
      for (int k = 0; k < 12000; ++k) {
        env.step();
        if (k % 10 != 0 || env.time() < toNanoseconds(12.0)) continue;
        sum += (tracker->currentSetpoint().position - quad.pose().position).norm();
        ++n;
      }
      mean[e] = sum / n;
    }
    INFO(kind << ": mean error ode " << mean[0] << " m, bullet " << mean[1] << " m");
    CHECK(std::abs(mean[1] - mean[0]) / mean[0] < 0.10);
    WARN(kind << ": mean tracking error ode " << mean[0] << " m, bullet " << mean[1] << " m");
  }
}

TEST_CASE("cross_engine: an engine refuses a saved body state it could not have produced, and keeps its own",
          "[physics][cross_engine][state]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  PhysicsSettings s;
  s.engine = engine;
  auto e = createPhysicEngine(s);
  MassProperties m;
  m.mass = 1;
  m.inertia = Mat3::Identity() * 0.01;
  BodyState start;
  start.pose.position = Vec3(1, 2, 3);
  start.angular_velocity = Vec3(0, 0, 1);
  e->addBody(m, {Shape::sphere(0.1)}, start);
  std::vector<Wrench> none(1);
  e->step(toNanoseconds(0.001), none);
  std::vector<std::byte> saved;
  StateWriter w(saved);
  e->saveState(w);
  std::vector<BodyState> before(1), after(1);
  e->readStates(before);
  // the last value both engines write of a body is its angular velocity about z (then the count
  // of run-time joints, none here)
  auto with_last = [&](double v) {
    std::vector<std::byte> bad = saved;
    std::memcpy(bad.data() + bad.size() - sizeof(std::uint64_t) - sizeof v, &v, sizeof v);
    return bad;
  };
  for (const auto& [value, message] : {std::pair{std::nan(""), "NaN or infinite"}, std::pair{1e7, "faster than"}}) {
    const std::vector<std::byte> bad = with_last(value);
    StateReader r(bad);
    CHECK_THROWS_WITH(e->restoreState(r), Catch::Contains(message));
    e->readStates(after);
    CHECK(after[0].pose.position == before[0].pose.position);
    CHECK(after[0].angular_velocity == before[0].angular_velocity);
  }
  StateReader good(saved);
  e->restoreState(good);
  e->readStates(after);
  CHECK(after[0].pose.position == before[0].pose.position);
}

TEST_CASE("cross_engine: substeps, forces off the centre of mass and restitution", "[physics][cross_engine]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  const double g = 9.81;
  {
    // 4 substeps of a 4 ms step are 4 steps of 1 ms: the closed form at h = 1 ms
    EnvironmentSettings s = settings(engine, 0.004);
    s.physics.substeps = 4;
    Environment env(s);
    Artifact& a = env.addArtifact("drop", at(0, 0, 100));
    a.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
    env.step(250);
    const int n = 1000;
    const double h = 0.001;
    CHECK(a.pose().position.z() == Approx(100.0 - g * h * h * n * (n + 1) / 2.0).margin(1e-9));
  }
  {
    // a force at the end of a bar, in its own frame, pushes and turns it
    Environment env(settings(engine, 0.001, false));
    Artifact& a = env.addArtifact("bar", at(0, 0, 0));
    a.addPhysicRoot(test::boxBody(Vec3(1.0, 0.1, 0.1), 1.0));
    a.setDriver(std::make_unique<test::LambdaDriver>([](Driver& d, const StepInfo& info) {
      if (info.step == 0) d.artifact().root().addForce(Vec3(0, 1, 0), Frame::World, Vec3(0.5, 0, 0), Frame::Local);
    }));
    env.step(3);
    const BodyState st = a.state();
    CHECK(st.linear_velocity.y() == Approx(0.001).margin(1e-12));
    CHECK(st.angular_velocity.z() == Approx(0.5 * 0.001 / ((1.0 + 0.01) / 12.0)).epsilon(1e-9));
  }
  {
    // a ball dropped from 1 m with restitution 0.5 comes back to about a quarter of the height
    EnvironmentSettings s = settings(engine, 0.001);
    s.physics.restitution = 0.5;
    Environment env(s);
    env.addGround();
    PhysicNodeSpec ball;
    ball.name = "ball";
    ball.shapes.push_back(Shape::sphere(0.05));
    ball.mass = 0.1;
    Artifact& a = env.addArtifact("ball", at(0, 0, 1.05));
    a.addPhysicRoot(ball);
    double lowest = 10, apex = 0;
    bool bounced = false;
    for (int k = 0; k < 1500; ++k) {
      env.step();
      const double z = a.pose().position.z() - 0.05;
      lowest = std::min(lowest, z);
      if (!bounced && a.state().linear_velocity.z() > 0) bounced = true;
      if (bounced) apex = std::max(apex, z);
    }
    INFO("rebound to " << apex << " m, lowest " << lowest << " m");
    CHECK(bounced);
    CHECK(apex == Approx(0.25).epsilon(0.1));
    CHECK(lowest > -0.005);  // it did not sink into the ground
  }
}

TEST_CASE("cross_engine: node frames offset from the centre of mass are tracked", "[physics][cross_engine]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  Environment env(settings(engine, 0.001, false));
  PhysicNodeSpec root;
  root.name = "hub";
  root.shapes.push_back(Shape::sphere(0.05));
  root.mass = 1.0;
  PhysicNodeSpec arm;
  arm.name = "tip";
  arm.pose.position = Vec3(1, 0, 0);
  arm.mass = 1.0;
  arm.inertia = Mat3::Identity() * 1e-3;
  root.addChild(arm);
  Artifact& a = env.addArtifact("dumbbell", at(0, 0, 0));
  a.addPhysicRoot(root);
  a.root().setVelocity(Vec3::Zero(), Vec3(0, 0, 1));  // spin about the hub's origin
  env.step();
  // the hub origin is 0.5 m from the centre of mass; both nodes keep 1 m apart and turn together
  const Pose hub = a.node("hub")->pose();
  const Pose tip = a.node("tip")->pose();
  CHECK((tip.position - hub.position).norm() == Approx(1.0).epsilon(1e-9));
  CHECK(hub.orientation.angularDistance(tip.orientation) < 1e-12);
  // the hub was given zero linear velocity at its origin, so the centre moves at w x r
  const Vec3 com = (hub.position + tip.position) / 2;
  CHECK(a.node("hub")->state().linear_velocity.norm() == Approx(0.0).margin(1e-3));
  CHECK((com - Vec3(0.5, 0.5 * 0.001, 0)).norm() < 1e-6);
}

TEST_CASE("cross_engine: a sweep's override of physics@engine chooses the engine, and its attributes are checked",
          "[scene][cross_engine]") {
  // what `ssx sweep` does with <parameter target="physics@engine">: an override applied before the
  // scene is read (hover_swarm.xml has a <physics> element; one is added where there is none)
  for (const char* scene : {"hover_swarm.xml", "quad_hover.xml"}) {
    INFO(scene);
    SceneOptions options;
    options.overrides.push_back({"physics@engine", "bullet", {}});
    Scene s = loadScene(kScenes / scene, options);
    CHECK(s.environment->settings().physics.engine == "bullet");
    s.environment->step(10);
    CHECK(s.environment->physics().name() == "bullet");
  }
  SceneOptions both;
  both.overrides.push_back({"physics@engine", "bullet", {"sweep.xml", 4}});
  both.overrides.push_back({"physics@sor", "1.2", {"sweep.xml", 5}});
  CHECK_THROWS_WITH(loadScene(kScenes / "hover_swarm.xml", both),
                    Catch::Contains("sweep.xml:5: error: <physics>: attribute 'sor' is an option of the ode engine"));
}
