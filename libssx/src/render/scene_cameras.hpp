#pragma once
// The scene's cameras and the camera images sensors ask for: where each camera is, the render
// items posed from the snapshot, the images drawn in the snapshot phase, and the frames handed to
// the frame thread. Owned by the Environment; used from the stepping thread only.
//
// The frames have a window in steps (RenderSettings::from, until, or attachRenderer while
// running): scheduled, then open (outputs opened, framing cameras placed, the frame thread
// running) from its first frame, closed (outputs finished) after its last one.

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

/// Throws ConfigError for render settings out of range (rates, sizes, fields of view, the window).
void checkRenderSettings(const RenderSettings& render);
/// Sets period_steps from rate_hz when given, else 25 frames per simulated second for cameras
/// given no period.
void resolveRenderPeriod(RenderSettings& render, Nanoseconds timestep);

class SceneCameras {
 public:
  using Artifacts = std::vector<std::unique_ptr<Artifact>>;
  using Log = std::function<void(std::string_view)>;

  SceneCameras();
  ~SceneCameras();
  SceneCameras(const SceneCameras&) = delete;
  SceneCameras& operator=(const SceneCameras&) = delete;

  /// At start, after the first snapshot: resolves what render roots follow; `timestep` for the
  /// time a frame shows, `warn` for what the user should know (no pixels, no ffmpeg).
  /// Camera sensors draw on `sensor_background` (the settings the run started with) whatever
  /// renderers are attached later.
  void bind(const Artifacts& artifacts, Nanoseconds timestep, const Color& sensor_background, Log warn);
  /// Frames of `settings` (period_steps resolved) from the first step at or after `now` that ends
  /// at or after settings.from, every period_steps, up to the last that ends by settings.until;
  /// opened at once when that first step is `now`. Closes nothing: close() the frames before.
  /// Throws ConfigError for a camera that follows no robot, before anything changes.
  void schedule(const RenderSettings& settings, std::int64_t now, const RenderEngine& renderer,
                const Artifacts& artifacts);
  /// Throws ConfigError for a camera of `settings` that follows no robot.
  static void checkCameras(const RenderSettings& settings, const Artifacts& artifacts);
  /// Whether a frame is due after step `step` (the render nodes are posed then even without a
  /// camera: renderNodes() serves viewers outside ssx).
  bool due(std::int64_t step) const noexcept {
    return period_ > 0 && step >= first_ && step <= last_ && (step - first_) % period_ == 0;
  }
  /// Whether the frame of `step` was the window's last.
  bool ended(std::int64_t step) const noexcept { return period_ > 0 && step > last_ - period_; }
  /// Draws what is queued, ends the frame thread, finishes the outputs, forgets the cameras;
  /// nothing is due any more. Throws Error naming what could not be finished.
  void close();

  /// A sensor's image request (see Environment::addCameraRequest).
  void addRequest(std::string owner, std::function<bool(std::int64_t, CameraView&)> due, Image& target);
  bool hasRequests() const noexcept { return !requests_.empty(); }
  /// Draws the images of the requests due at `step` from the snapshot. Throws StepError.
  void renderRequests(std::int64_t step, RenderEngine& renderer, const Artifacts& artifacts);
  /// Hands the scene cameras' views of the snapshot at `step` to the frame thread, stamped with
  /// `time` (< 0: the time after that step); opens the frames first when they are not. Closes
  /// them after the window's last frame (`close_after`: a step's frame). Throws StepError.
  void drawFrame(std::int64_t step, const Artifacts& artifacts, Nanoseconds time = -1,
                 std::span<const RenderNode> overlay = {}, bool close_after = false);
  /// Forgets the posed items (after a restore: the snapshot changed under the same step count).
  void invalidate() noexcept { items_step_ = -1; }

  const std::vector<RenderNode>& renderNodes() const noexcept { return items_; }
  std::vector<CameraSpec> specs() const;
  std::int64_t frameCount() const noexcept { return frames_; }

 private:
  // poses every render node from the snapshot, once per step
  void sync(std::int64_t step, const Artifacts& artifacts);
  // opens the outputs and places the cameras (a framing one around what is placed now)
  void open(const Artifacts& artifacts);
  // the cameras' views of the posed items, to the frame thread
  void submit(std::int64_t step, const Artifacts& artifacts, Nanoseconds time, std::span<const RenderNode> overlay);

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
  Log warn_;
  Color sensor_background_{};
  std::int64_t frames_ = 0;
  // the window: frames at first_, first_ + period_, ... up to last_ (period_ 0: none)
  RenderSettings settings_;
  bool draws_pixels_ = false;
  std::string engine_;
  std::int64_t period_ = 0, first_ = 0, last_ = 0;
  bool open_ = false;
};

}  // namespace ssx::detail
