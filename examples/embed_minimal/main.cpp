// embed_minimal: builds a scene in code with libssx, runs it for 5 s in real time and prints the
// timing summary. Boxes fall onto the ground; one body is held at 1 m by a small PD driver that
// reads the body's state from the snapshot and pushes it with a force.
#include <ssx/ssx.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

// a PD position hold: force = m (kp (target - p) - kd v) + weight compensation
class HoldDriver final : public ssx::Driver {
 public:
  void configure(const ssx::Descriptor& params, ssx::PluginSetup& /*setup*/) override {
    target_ = params.get<ssx::Vec3>("target", ssx::Vec3(0, 0, 1));
    kp_ = params.getPositive("kp", 20.0);
    kd_ = params.getPositive("kd", 8.0);
    mass_ = ssx::combinedMass(artifact().root().spec()).mass;
    gravity_ = environment().settings().physics.gravity;
  }
  void step(const ssx::StepInfo&) override {
    ssx::PhysicNode& body = artifact().root();
    const ssx::BodyState s = body.state();
    const ssx::Vec3 f = mass_ * (kp_ * (target_ - s.pose.position) - kd_ * s.linear_velocity - gravity_);
    body.addForce(f);
  }

 private:
  ssx::Vec3 target_, gravity_;
  double kp_ = 0, kd_ = 0, mass_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
  ssx::EnvironmentSettings settings;
  settings.timestep = ssx::toNanoseconds(0.002);  // 500 Hz
  settings.seed = 42;
  ssx::Environment env(settings);
  env.addGround();

  // a few boxes falling from different heights
  for (int i = 0; i < 5; ++i) {
    ssx::PhysicNodeSpec box;
    box.name = "body";
    box.shapes.push_back(ssx::Shape::box(ssx::Vec3(0.2, 0.2, 0.2)));
    box.mass = 1.0;
    env.addArtifact("box" + std::to_string(i), {ssx::Vec3(i * 0.5, 0, 0.5 + 0.4 * i), ssx::Quat::Identity()})
        .addPhysicRoot(box);
  }

  // a sphere held up by the PD driver, starting on the ground
  ssx::PhysicNodeSpec ball;
  ball.name = "body";
  ball.shapes.push_back(ssx::Shape::sphere(0.1));
  ball.mass = 0.5;
  ssx::Artifact& held = env.addArtifact("held", {ssx::Vec3(-1, 0, 0.1), ssx::Quat::Identity()});
  held.addPhysicRoot(ball);
  ssx::Descriptor params("driver");
  params.set("target", ssx::Vec3(-1, 0, 1.0));
  held.setDriver(std::make_unique<HoldDriver>(), params, 1, "hold");

  ssx::RunOptions run;
  run.mode = ssx::RunOptions::Mode::RealTime;
  run.steps = static_cast<std::int64_t>(seconds / ssx::toSeconds(settings.timestep) + 0.5);
  std::printf("embed_minimal: %zu artifacts, %d threads, %.1f s of simulated time in real time\n", env.artifactCount(),
              static_cast<int>(env.threadCount()), seconds);
  const ssx::TimingSummary summary = env.run(run);

  const ssx::Vec3 p = held.pose().position;
  std::printf("held body at (%.3f, %.3f, %.3f), target (-1, 0, 1)\n", p.x(), p.y(), p.z());
  for (int i = 0; i < 5; ++i) {
    const ssx::Vec3 b = env.findArtifact("box" + std::to_string(i))->pose().position;
    std::printf("box%d resting at z = %.4f m (half size 0.1 m)\n", i, b.z());
  }
  std::printf("%s\n", summary.str().c_str());
  return 0;
}
