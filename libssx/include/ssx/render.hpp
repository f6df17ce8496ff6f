#pragma once
/// @file
/// Rendering: render node trees, cameras, images and the abstract render engine.
///
/// Engines: `null` (the default) draws nothing and costs nothing; `osmesa` draws with software
/// OpenGL offscreen (no display needed). Nothing of OpenGL appears in this header.
///
/// Two kinds of pictures are made:
/// - **frames** of the scene's cameras (`<render>`/`<camera>`), at a rate in simulated time, drawn
///   in the render phase after the drivers, written as PNG files, an MP4 and/or a snapshot;
/// - **camera sensor images**, drawn in the snapshot phase of the step they are due in (see
///   Environment::addCameraRequest), from that step's snapshot.
/// Both are drawn on the thread that calls Environment::step, one at a time.

#include <ssx/export.hpp>
#include <ssx/error.hpp>
#include <ssx/types.hpp>
#include <ssx/physic_node.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace ssx {

class Artifact;

using Color = std::array<float, 4>;  ///< RGBA, 0..1

/// One node of what the user sees, posed relative to its parent. A root follows the physic node
/// named in `follow` (its pose is then relative to that node), or stays where it was placed.
struct RenderNodeSpec {
  /// The shape drawn; None draws nothing (a frame for children). Cylinders and capsules lie
  /// along z; a plane is the z = 0 plane of the node.
  enum class Primitive : std::uint8_t { None, Box, Sphere, Cylinder, Capsule, Plane, Mesh };
  std::string name;                       ///< for messages; may be empty
  Primitive primitive = Primitive::None;  ///< what is drawn
  Vec3 size = Vec3::Ones();  ///< box edge lengths; plane: x and y extent
  double radius = 0.5;       ///< sphere, cylinder, capsule: m
  double length = 1.0;       ///< cylinder, capsule: length of the straight part, m
  std::shared_ptr<const TriangleMesh> mesh;  ///< the mesh drawn (Primitive::Mesh), in this node's frame
  Color color{0.7f, 0.7f, 0.7f, 1.0f};  ///< RGBA, 0..1
  bool grid = false;  ///< draw a 1 m grid on it (the ground)
  Pose pose;          ///< relative to the parent (a root: to the followed node, or the artifact)
  std::string follow;  ///< physic node name (roots only); empty: fixed
  std::vector<RenderNodeSpec> children;  ///< posed relative to this node
};

/// The largest width or height of an image, in pixels, for frames and camera sensors alike.
inline constexpr int kMaxImageSide = 16384;
/// Whether a horizontal field of view, in degrees, can be drawn: in (0, 180).
constexpr bool validFieldOfView(double fov_deg) { return fov_deg > 0 && fov_deg < 180; }

/// A camera's pose and lens. The camera looks along its +x axis with +z up (the robotics body
/// convention), so a camera on a robot looks where the robot's nose points.
struct CameraView {
  Pose pose;              ///< where the camera is and where it looks (+x forward, +z up), world frame
  double fov_deg = 60.0;  ///< horizontal field of view
  int width = 640;        ///< pixels
  int height = 480;       ///< pixels
  double near = 0.05;     ///< nearest distance drawn, m
  double far = 200.0;     ///< farthest distance drawn, m
  bool depth = false;               ///< also read the depth image
  /// Draw a shadow on the ground under every robot (an artifact with a dynamic root), as if lit
  /// from straight above: the scene's cameras do (RenderSettings::shadows), camera sensors not.
  bool shadows = false;
};

/// An image: rows top to bottom, RGB 8 bits each; depth (when asked for) in m along the optical
/// axis, +infinity where nothing was hit.
struct Image {
  int width = 0;                  ///< pixels
  int height = 0;                 ///< pixels
  std::vector<std::uint8_t> rgb;  ///< width * height * 3 bytes, row by row from the top
  std::vector<float> depth;       ///< width * height values, or empty when not asked for
  /// The R, G, B bytes of pixel (x, y), x from the left, y from the top (unchecked).
  const std::uint8_t* pixel(int x, int y) const { return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x); }
  /// The depth at pixel (x, y), m (std::out_of_range without a depth image).
  float depthAt(int x, int y) const { return depth.at(static_cast<std::size_t>(y) * width + x); }
};

/// A camera of the scene: fixed (`position` looking at `look_at`), or following an artifact
/// (`position` and `look_at` then in that artifact's first root's frame, yaw only: the picture
/// stays level). Its frames go to the outputs given.
struct CameraSpec {
  std::string name = "main";    ///< unique among the scene's cameras
  Vec3 position{8, -8, 6};      ///< m, world frame (or the followed artifact's)
  Vec3 look_at = Vec3::Zero();  ///< the point at the centre of the picture, same frame
  std::string follow;  ///< artifact name; empty: fixed
  SourceLocation follow_from;  ///< where `follow` was given (a camera of a scene file)
  SourceLocation where;        ///< where the camera was given (its element in a scene file)
  bool frame_scene = false;  ///< set position and look_at at start so that every artifact is in view
  double fov_deg = 60.0;  ///< horizontal field of view, degrees
  std::filesystem::path frames_dir;  ///< PNG per frame (frame_000000.png, ...); empty: none
  std::filesystem::path video;       ///< MP4 through ffmpeg; empty: none
  std::filesystem::path snapshot;    ///< PNG of the last frame drawn, written when the run stops
};

/// Settings of the render engine.
struct RenderSettings {
  std::string engine = "null";    ///< "null" (draws nothing) or "osmesa" (software OpenGL)
  double rate_hz = 0;             ///< frames per simulated second; 0: as often as period_steps says
  std::int64_t period_steps = 0;  ///< draw every this many steps; 0: never (set from rate_hz if given)
  int width = 640;                ///< frame width, pixels
  int height = 480;               ///< frame height, pixels
  Color background{0.62f, 0.72f, 0.85f, 1.0f};  ///< the sky, RGBA 0..1
  bool shadows = true;     ///< the scene cameras draw each robot's shadow on the ground
  bool time_stamp = true;  ///< the scene cameras' frames show the simulated time, top left
  std::vector<CameraSpec> cameras;  ///< frames are drawn only when there is a camera
  /// The frames start with the first step that ends at or after this simulated time, ns (0: the
  /// first step): the cameras' outputs are opened and the cameras framing the scene placed then.
  Nanoseconds from = 0;
  /// The frames end with the last step that ends at or before this simulated time, ns, and the
  /// outputs are finished then (a video closed, a snapshot written); < 0: when the run stops.
  Nanoseconds until = -1;
};

/// A live render node: one node of an artifact's render tree, posed in the world from the
/// snapshot by the Environment right before drawing.
struct RenderNode {
  const RenderNodeSpec* spec = nullptr;  ///< what to draw (owned by the artifact)
  const Artifact* artifact = nullptr;    ///< whose node it is
  Pose world;                            ///< the node's pose in the world
};

/// An abstract renderer. Called only from the thread calling Environment::step.
class SSX_EXPORT RenderEngine {
 public:
  virtual ~RenderEngine();
  /// The engine's name, as RenderSettings::engine gives it.
  virtual std::string name() const = 0;
  /// False for the null engine: renderView must not be called.
  virtual bool drawsPixels() const = 0;
  /// Draws the nodes as seen by `view` into `out` (resized to the view).
  virtual void renderView(const CameraView& view, const std::vector<RenderNode>& nodes, const Color& background,
                          Image& out) = 0;
};

/// Creates a render engine by name ("null", and "osmesa" when built with it); throws
/// ConfigError for an unknown name, naming the ones available.
SSX_EXPORT std::unique_ptr<RenderEngine> createRenderEngine(const RenderSettings& settings);
/// The engine names this build knows.
SSX_EXPORT std::vector<std::string> renderEngineNames();

/// Writes an RGB image as PNG (fast compression); throws Error naming the file if it cannot.
SSX_EXPORT void writePng(const std::filesystem::path& file, const Image& image);

}  // namespace ssx
