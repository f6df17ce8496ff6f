#pragma once
// The shapes of the viewer's scene message (docs/viewer.md, "What a page receives"): each render
// tree's shapes as JSON, posed in its body's frame or the world's, and the meshes they draw, each
// file's once.
#include <ssx/render.hpp>

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace ssx::viewer {

/// The meshes a scene draws, each file's once: the shapes name them by their index.
struct MeshTable {
  std::map<const TriangleMesh*, std::size_t> index;  ///< each mesh's place in `meshes`
  std::vector<const TriangleMesh*> meshes;           ///< in the order first drawn

  /// The mesh's index, given it now if it has none.
  std::size_t of(const TriangleMesh* mesh);
  /// [{"vertices":[x,y,z,...],"triangles":[i,j,k,...]},...]: metres to a micrometre (floats on the page).
  std::string json() const;
};

/// Appends the shapes of render tree `n` to `out` as JSON objects (a comma before each but the
/// first: `first` says whether one was written), each posed in the frame `parent` is given in (a
/// body's root, or the world); a mesh names its entry of `meshes` and gives its bounding box as
/// its size and how far it reaches from its origin.
void shapes(std::string& out, const RenderNodeSpec& n, const Pose& parent, bool& first, MeshTable& meshes);

}  // namespace ssx::viewer
