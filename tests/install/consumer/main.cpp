// Builds a tiny scene with the installed libssx, checks that a dropped box lands, and that a
// saved state replays the same fall.
#include <ssx/ssx.hpp>

#include <cstdio>

int main() {
  ssx::Environment env;
  env.addGround();
  ssx::PhysicNodeSpec box;
  box.name = "body";
  box.shapes.push_back(ssx::Shape::box(ssx::Vec3(0.2, 0.2, 0.2)));
  box.mass = 1.0;
  ssx::Artifact& a = env.addArtifact("box", {ssx::Vec3(0, 0, 1), ssx::Quat::Identity()});
  a.addPhysicRoot(box);
  env.step(100);
  const std::vector<std::byte> saved = env.saveState();
  env.step(1900);
  const double z = a.pose().position.z();
  env.restoreState(saved);
  env.step(1900);
  const bool replayed = a.pose().position.z() == z;
  std::printf("ssx %s: box at z = %.4f after %.1f s; replayed from a saved state: %s\n", SSX_VERSION_STRING, z,
              ssx::toSeconds(env.time()), replayed ? "identical" : "DIFFERENT");
  return (z > 0.09 && z < 0.11 && replayed) ? 0 : 1;
}
