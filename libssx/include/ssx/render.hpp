#pragma once
/// @file
/// The abstract render engine and render node trees. The `null` engine (the default) draws
/// nothing and costs nothing; an offscreen OpenGL backend comes later.

#include <ssx/export.hpp>
#include <ssx/types.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ssx {

class Artifact;

/// One node of what the user sees, posed relative to its parent. A root follows the physic node
/// named in `follow` (its pose is then relative to that node), or stays where it was placed.
struct RenderNodeSpec {
  enum class Primitive : std::uint8_t { None, Box, Sphere, Cylinder, Capsule, Plane };
  std::string name;
  Primitive primitive = Primitive::None;
  Vec3 size = Vec3::Ones();  ///< box edge lengths; plane: x and y extent
  double radius = 0.5;
  double length = 1.0;
  std::array<float, 4> color{0.7f, 0.7f, 0.7f, 1.0f};  ///< RGBA, 0..1
  Pose pose;
  std::string follow;  ///< physic node name (roots only); empty: fixed
  std::vector<RenderNodeSpec> children;
};

/// Settings of the render engine.
struct RenderSettings {
  std::string engine = "null";
  std::int64_t period_steps = 0;  ///< draw every this many steps; 0: never
};

/// A live render node: one node of an artifact's render tree, posed in the world from the
/// snapshot by the Environment right before `draw`.
struct RenderNode {
  const RenderNodeSpec* spec = nullptr;
  const Artifact* artifact = nullptr;
  Pose world;
};

/// An abstract renderer. Called only from the thread calling Environment::step, in the render
/// phase, after drivers; it reads the snapshot through the nodes the Environment hands it.
class SSX_EXPORT RenderEngine {
 public:
  virtual ~RenderEngine();
  virtual std::string name() const = 0;
  /// Draws one frame of the given nodes at simulated time `time`.
  virtual void draw(Nanoseconds time, const std::vector<RenderNode>& nodes) = 0;
  /// Frames drawn so far.
  virtual std::int64_t frameCount() const = 0;
};

/// Creates a render engine by name ("null"); throws ConfigError for an unknown name.
SSX_EXPORT std::unique_ptr<RenderEngine> createRenderEngine(const RenderSettings& settings);

}  // namespace ssx
