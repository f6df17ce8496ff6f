#pragma once
// The scene's cameras and the camera images sensors ask for: where each camera is, the render
// items posed from the snapshot, the images drawn in the snapshot phase, and the frames handed to
// the frame thread. Owned by the Environment; used from the stepping thread only.

#include <ssx/artifact.hpp>
#include <ssx/render.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <span>
#include <vector>

namespace ssx::detail {

class FrameWorker;

class SceneCameras {
 public:
  using Artifacts = std::vector<std::unique_ptr<Artifact>>;
  using Log = std::function<void(std::string_view)>;

  SceneCameras();
  ~SceneCameras();
  SceneCameras(const SceneCameras&) = delete;
  SceneCameras& operator=(const SceneCameras&) = delete;

  /// At start, after the first snapshot: resolves what render roots follow, places the cameras
  /// (those framing the scene around what is placed) and starts the frame thread. `warn` gets
  /// what the user should know (no pixels, no ffmpeg). Throws ConfigError.
  void start(const RenderSettings& settings, Nanoseconds timestep, const RenderEngine& renderer,
             const Artifacts& artifacts, const Log& warn);
  /// Flushes and stops the frame thread (errors go to `error`); forgets the cameras.
  void finish(const Log& error);

  /// A sensor's image request (see Environment::addCameraRequest).
  void addRequest(std::string owner, std::function<bool(std::int64_t, CameraView&)> due, Image& target);
  bool hasRequests() const noexcept { return !requests_.empty(); }
  /// Draws the images of the requests due at `step` from the snapshot. Throws StepError.
  void renderRequests(std::int64_t step, RenderEngine& renderer, const Color& background, const Artifacts& artifacts);
  /// Hands the scene cameras' views of the snapshot at `step` to the frame thread, stamped with
  /// `time` (< 0: the time after that step). Throws StepError.
  void drawFrame(std::int64_t step, const RenderSettings& settings, const Artifacts& artifacts, Nanoseconds time = -1,
                 std::span<const RenderNode> overlay = {});
  /// Forgets the posed items (after a restore: the snapshot changed under the same step count).
  void invalidate() noexcept { items_step_ = -1; }

  const std::vector<RenderNode>& renderNodes() const noexcept { return items_; }
  std::vector<CameraSpec> specs() const;
  std::int64_t frameCount() const noexcept { return frames_; }

 private:
  // poses every render node from the snapshot, once per step
  void sync(std::int64_t step, const Artifacts& artifacts);

  struct Camera {
    CameraSpec spec;
    const Artifact* follow = nullptr;
    Eigen::AlignedBox3d seen;  // a framing camera's: every place the robots have been in a frame
  };
  struct Request {
    std::string owner;
    std::function<bool(std::int64_t, CameraView&)> due;
    Image* target;
  };
  std::vector<Camera> cameras_;
  std::vector<Request> requests_;
  std::vector<std::vector<const PhysicNode*>> follow_;  // per artifact, per render root
  std::vector<RenderNode> items_;
  std::int64_t items_step_ = -1;  // the step items_ were posed for
  std::unique_ptr<FrameWorker> worker_;
  Nanoseconds timestep_ = 0;  // for the time a frame shows
  std::int64_t frames_ = 0;
};

}  // namespace ssx::detail
