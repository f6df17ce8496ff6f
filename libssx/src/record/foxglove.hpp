#pragma once
// Channels in Foxglove's well-known schemas (https://docs.foxglove.dev/docs/visualization/message-schemas),
// JSON-encoded, so that Foxglove and Lichtblick draw a recording in their 3D panel:
// - /tf, foxglove.FrameTransforms: one transform per recorded body per sample, "world" -> body name;
// - /scene, foxglove.SceneUpdate: once, the shapes of every render tree as entities locked to
//   their body's frame (or to "world" when fixed).
// JSON rather than protobuf: no new dependency, readable in any tool, and Foxglove decodes both.

#include "base/json.hpp"

#include <ssx/render.hpp>
#include <ssx/types.hpp>

#include <span>
#include <string>
#include <vector>

namespace ssx::detail {

/// The fixed frame every transform starts from.
inline constexpr const char* kWorldFrame = "world";

/// JSON Schemas of the two messages (only the fields written), kept in the file with each channel.
extern const char* const kFrameTransformsSchema;
extern const char* const kSceneUpdateSchema;

/// foxglove.FrameTransforms for one sample: positions (N x 3) and orientations (N x 4, w x y z),
/// as Recording decodes them, of the bodies `names`.
std::string frameTransforms(Nanoseconds time, std::span<const std::string> names, std::span<const float> positions,
                            std::span<const float> orientations);

/// A shape to draw, in the frame of a recorded body (or of "world").
struct SceneShape {
  std::string frame;  ///< a body's name, or kWorldFrame
  const RenderNodeSpec* spec = nullptr;
  Pose pose;  ///< the node's pose in that frame
};

/// foxglove.SceneUpdate with one entity per frame, holding its shapes (boxes as cubes, spheres,
/// cylinders; a capsule as a cylinder and two spheres; a plane as a thin cube). Nodes that draw
/// nothing are left out.
std::string sceneUpdate(Nanoseconds time, std::span<const SceneShape> shapes);

}  // namespace ssx::detail
