// Builds a tiny scene with the installed libssx and checks that a dropped box lands.
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
  env.step(2000);
  const double z = a.pose().position.z();
  std::printf("ssx %s: box at z = %.4f after %.1f s\n", SSX_VERSION_STRING, z, ssx::toSeconds(env.time()));
  return (z > 0.09 && z < 0.11) ? 0 : 1;
}
