#pragma once
// Meshes read once per file and scale, shared by every shape and render node that uses them.

#include <ssx/physic_node.hpp>

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <tuple>

namespace ssx::detail {

namespace fs = std::filesystem;

class MeshCache {
 public:
  // the mesh in `file`, scaled, with its hull; nullptr with `problem` said when it cannot be read
  // or is empty or flat
  std::shared_ptr<const TriangleMesh> load(const fs::path& file, const Vec3& scale, std::string& problem);
  // seconds spent reading meshes and computing their hulls
  double seconds() const noexcept { return seconds_; }

 private:
  std::map<std::tuple<std::string, double, double, double>, std::shared_ptr<const TriangleMesh>> meshes_;
  double seconds_ = 0;
};

}  // namespace ssx::detail
