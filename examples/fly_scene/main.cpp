// Loads a scene and flies its quadrotors from a program: to set-points on a circle, then by velocity.
#include <ssx/ssx.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

namespace {

int fly(const std::filesystem::path& file) {
  ssx::Scene scene = ssx::loadScene(file);
  ssx::Environment& env = *scene.environment;
  // the robots this program can fly: drivers that take position and velocity commands
  std::vector<ssx::Artifact*> quads;
  for (ssx::Artifact* a : env.selectArtifacts("*"))
    if (const auto* d = dynamic_cast<ssx::CommandInterface*>(a->driver());
        d != nullptr && d->acceptsCommand(ssx::CommandLevel::Position) && d->acceptsCommand(ssx::CommandLevel::Velocity))
      quads.push_back(a);
  if (quads.empty()) {
    std::fprintf(stderr,
                 "ssx_fly_scene: %s has no robot whose driver takes position and velocity commands (quadrotors do): "
                 "nothing to fly\n",
                 file.c_str());
    return 2;
  }
  env.step(1500);  // 3 s: they take off to their hover points

  // position level: each to its place on a circle of 1.5 m at 2 m height, facing the centre
  for (std::size_t i = 0; i < quads.size(); ++i) {
    const double angle = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(quads.size());
    ssx::Setpoint sp;
    sp.position = ssx::Vec3(1.5 * std::cos(angle), 1.5 * std::sin(angle), 2.0);
    sp.yaw = angle + std::numbers::pi;
    dynamic_cast<ssx::CommandInterface&>(*quads[i]->driver()).setSetpoint(sp);
  }
  env.step(5000);  // 10 s
  for (const ssx::Artifact* a : quads) {
    const auto* input = dynamic_cast<const ssx::CommandInterface*>(a->driver());
    const double error = (a->pose().position - input->currentSetpoint().position).norm();
    std::printf("%s: %.3f m from its set-point\n", a->name().c_str(), error);
  }

  // velocity level: the first climbs at 0.5 m/s for 2 s, the others hold their places
  auto& first = dynamic_cast<ssx::CommandInterface&>(*quads[0]->driver());
  first.setCommand(ssx::Command::velocityYawRate(ssx::Vec3(0, 0, 0.5)));
  const double z0 = quads[0]->pose().position.z();
  env.step(1000);
  std::printf("%s climbed %.2f m in 2 s\n", quads[0]->name().c_str(), quads[0]->pose().position.z() - z0);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // a scene file, or the installed quad_hover.xml (three quadrotors)
  try {
    return fly(argc > 1 ? std::filesystem::path(argv[1]) : ssx::installedDataDirectory() / "scenes" / "quad_hover.xml");
  } catch (const std::exception& e) {  // a scene that does not load (its diagnostics), a run that fails
    std::fprintf(stderr, "ssx_fly_scene: %s\n", e.what());
    return 2;
  }
}
