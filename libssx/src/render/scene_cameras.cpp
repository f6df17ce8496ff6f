#include "render/scene_cameras.hpp"

#include "render/frame_output.hpp"
#include "render/frame_worker.hpp"

#include <ssx/environment.hpp>
#include <ssx/error.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace ssx::detail {

namespace {

// a camera at `position` looking at `target`, level (its y axis horizontal)
Pose lookAt(const Vec3& position, const Vec3& target) {
  Vec3 forward = target - position;
  if (forward.norm() < 1e-9) forward = Vec3::UnitX();
  forward.normalize();
  Vec3 left = Vec3::UnitZ().cross(forward);
  if (left.norm() < 1e-6) left = Vec3::UnitY();  // looking straight up or down
  left.normalize();
  Eigen::Matrix3d r;
  r.col(0) = forward;
  r.col(1) = left;
  r.col(2) = forward.cross(left);
  return Pose{position, Quat(r).normalized()};
}

// everything placed, static or not (ground planes aside), seen from the south-east above
// the box of the robots' positions (the ground left out)
Eigen::AlignedBox3d robotsBox(const SceneCameras::Artifacts& artifacts) {
  Eigen::AlignedBox3d box;
  for (const auto& a : artifacts) {
    if (a->rootCount() == 0) {
      box.extend(a->placement().position);
      continue;
    }
    const auto& shapes = a->root().spec().shapes;
    const bool ground = !shapes.empty() && std::all_of(shapes.begin(), shapes.end(), [](const Shape& s) {
      return s.kind == Shape::Kind::Plane;
    });
    if (!ground) box.extend(a->root().pose().position);
  }
  if (box.isEmpty()) box.extend(Vec3::Zero());
  return box;
}

// a camera seeing the whole box: looking at its centre from the side and above, as close as keeps
// every corner of the box, grown by 0.5 m, inside the image (both ways)
void frameBox(CameraSpec& spec, Eigen::AlignedBox3d box, double aspect) {
  box.min() -= Vec3::Constant(0.5);
  box.max() += Vec3::Constant(0.5);
  const Vec3 centre = box.center();
  const Vec3 back = Vec3(0.62, -0.62, 0.48).normalized();  // from the centre towards the camera
  const Vec3 forward = -back;
  const Vec3 right = forward.cross(Vec3::UnitZ()).normalized();
  const Vec3 up = right.cross(forward);
  const double tan_v = std::tan(spec.fov_deg * std::numbers::pi / 360.0);
  const double tan_h = tan_v * aspect;
  double distance = 1.0;
  for (int k = 0; k < 8; ++k) {
    const Vec3 r = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k)) - centre;
    // the corner's depth from a camera at centre + D back is D + r.forward: far enough that its
    // offsets across the image fit the half angles
    distance = std::max({distance, std::abs(r.dot(right)) / tan_h - r.dot(forward),
                         std::abs(r.dot(up)) / tan_v - r.dot(forward)});
  }
  spec.look_at = centre;
  spec.position = centre + 1.05 * distance * back;
}

}  // namespace

void checkRenderSettings(const RenderSettings& r) {
  auto bad = [](const std::string& what) { throw ConfigError({}, what); };
  if (r.period_steps < 0) bad("render period must be 0 (never) or positive");
  if (!(r.rate_hz == 0 || (r.rate_hz >= kMinRateHz && std::isfinite(r.rate_hz))))
    bad("render rate_hz must be 0 (none) or at least 1e-6");
  if (r.width < 1 || r.height < 1 || r.width > kMaxImageSide || r.height > kMaxImageSide)
    bad("render width and height must be in 1.." + std::to_string(kMaxImageSide));
  for (const auto& c : r.cameras)
    if (!validFieldOfView(c.fov_deg)) bad("camera '" + c.name + "': fov_deg must be in (0, 180)");
  if (r.from < 0 || r.from > toNanoseconds(kMaxDurationSeconds))
    bad("render from must be a simulated time in 0.." + std::to_string(static_cast<long long>(kMaxDurationSeconds)) + " s");
  if (r.until >= 0 && r.until < r.from) bad("render until must not come before from (or be negative: until the end)");
}

void resolveRenderPeriod(RenderSettings& r, Nanoseconds timestep) {
  if (r.rate_hz > 0) r.period_steps = std::max<std::int64_t>(1, std::llround(1.0 / (r.rate_hz * toSeconds(timestep))));
  // a camera with somewhere to put its frames and no rate given: 25 frames per simulated second
  if (r.period_steps == 0 && !r.cameras.empty())
    r.period_steps = std::max<std::int64_t>(1, std::llround(1.0 / (25.0 * toSeconds(timestep))));
}

SceneCameras::SceneCameras() = default;
SceneCameras::~SceneCameras() = default;

void SceneCameras::bind(const Artifacts& artifacts, Nanoseconds timestep, const Color& sensor_background, Log warn) {
  timestep_ = timestep;
  sensor_background_ = sensor_background;
  warn_ = std::move(warn);
  // render roots follow their physic nodes, looked up once
  follow_.clear();
  for (const auto& a : artifacts) {
    auto& follow = follow_.emplace_back();
    for (const auto& root : a->renderRoots()) follow.push_back(root->follow.empty() ? nullptr : a->node(root->follow));
  }
}

void SceneCameras::schedule(const RenderSettings& r, std::int64_t now, const RenderEngine& renderer,
                            const Artifacts& artifacts) {
  checkCameras(r, artifacts);
  settings_ = r;
  draws_pixels_ = renderer.drawsPixels();
  engine_ = renderer.name();
  period_ = r.period_steps;
  // step s ends at (s + 1) timesteps: the first ending at or after `from`, the last by `until`
  first_ = std::max(now, (r.from + timestep_ - 1) / timestep_ - 1);
  last_ = r.until < 0 ? std::numeric_limits<std::int64_t>::max() : r.until / timestep_ - 1;
  if (period_ > 0 && first_ == now && first_ <= last_) {
    try {
      open(artifacts);
    } catch (...) {
      period_ = 0;  // nothing scheduled
      throw;
    }
  }
}

void SceneCameras::checkCameras(const RenderSettings& r, const Artifacts& artifacts) {
  for (const CameraSpec& spec : r.cameras) {
    if (spec.follow.empty()) continue;
    const auto it = std::find_if(artifacts.begin(), artifacts.end(), [&](const auto& a) { return a->name() == spec.follow; });
    if (it == artifacts.end() || (*it)->rootCount() == 0)
      throw ConfigError({}, "camera '" + spec.name + "' follows '" + spec.follow +
                                "', which is no artifact with a physic root");
  }
}

void SceneCameras::open(const Artifacts& artifacts) {
  const RenderSettings& r = settings_;
  open_ = true;
  if (r.cameras.empty()) return;
  if (!draws_pixels_) {
    std::string names;
    for (const auto& c : r.cameras) names += (names.empty() ? "'" : ", '") + c.name + "'";
    warn_("render engine '" + engine_ + "' draws no pixels: camera " + names +
          " gets no frames (choose engine=\"osmesa\" in <render> or --render osmesa)");
    return;
  }
  for (const CameraSpec& spec : r.cameras) {
    Camera c;
    c.spec = spec;
    for (const auto& a : artifacts)
      if (!spec.follow.empty() && a->name() == spec.follow) c.follow = a.get();  // (checked by schedule)
    if (spec.frame_scene) {
      c.seen = robotsBox(artifacts);
      frameBox(c.spec, c.seen, static_cast<double>(r.width) / r.height);
    }
    cameras_.push_back(std::move(c));
  }
  const double fps = 1.0 / (static_cast<double>(r.period_steps) * toSeconds(timestep_));
  try {
    std::vector<std::unique_ptr<FrameOutput>> outputs;
    for (const auto& c : cameras_) outputs.push_back(std::make_unique<FrameOutput>(c.spec, fps, warn_));
    worker_ = std::make_unique<FrameWorker>(r, std::move(outputs));
  } catch (...) {
    cameras_.clear();
    open_ = false;
    throw;
  }
}

void SceneCameras::close() {
  period_ = 0;
  open_ = false;
  cameras_.clear();
  if (!worker_) return;
  const std::unique_ptr<FrameWorker> worker = std::move(worker_);
  try {
    worker->finish();
  } catch (const std::exception& e) {
    throw Error(std::string("frames: ") + e.what());
  }
}

std::vector<CameraSpec> SceneCameras::specs() const {
  std::vector<CameraSpec> out;
  for (const auto& c : cameras_) out.push_back(c.spec);
  return out;
}

void SceneCameras::addRequest(std::string owner, std::function<bool(std::int64_t, CameraView&)> due, Image& target) {
  requests_.push_back({std::move(owner), std::move(due), &target});
}

void SceneCameras::sync(std::int64_t step, const Artifacts& artifacts) {
  if (items_step_ == step) return;
  items_step_ = step;
  items_.clear();
  const Artifact* owner = nullptr;
  auto add = [&](auto& self, const RenderNodeSpec& spec, const Pose& parent) -> void {
    const Pose world = parent * spec.pose;
    items_.push_back({&spec, owner, world});
    for (const auto& c : spec.children) self(self, c, world);
  };
  for (std::size_t k = 0; k < artifacts.size(); ++k) {
    const Artifact& a = *artifacts[k];
    owner = &a;
    for (std::size_t i = 0; i < a.renderRoots().size(); ++i) {
      const PhysicNode* follow = follow_[k][i];
      add(add, *a.renderRoots()[i], follow != nullptr ? follow->pose() : a.placement());
    }
  }
}

void SceneCameras::renderRequests(std::int64_t step, RenderEngine& renderer, const Artifacts& artifacts) {
  CameraView view;
  for (auto& r : requests_) {
    try {
      view = CameraView{};
      if (!r.due(step, view)) continue;
      sync(step + 1, artifacts);
      renderer.renderView(view, items_, sensor_background_, *r.target);
    } catch (const std::exception& e) {
      throw StepError("", r.owner, step, std::string("camera image: ") + e.what());
    }
  }
}

void SceneCameras::drawFrame(std::int64_t step, const Artifacts& artifacts, Nanoseconds time,
                             std::span<const RenderNode> overlay, bool close_after) {
  sync(step + 1, artifacts);  // also without cameras: renderNodes() serves viewers outside ssx
  if (period_ > 0 && !open_) {
    try {
      open(artifacts);
    } catch (const std::exception& e) {
      throw StepError("", "render", step, std::string("starting the frames: ") + e.what());
    }
  }
  if (worker_) submit(step, artifacts, time, overlay);
  if (close_after && ended(step)) {
    try {
      close();
    } catch (const std::exception& e) {
      throw StepError("", "render", step, std::string("finishing the frames: ") + e.what());
    }
  }
}

void SceneCameras::submit(std::int64_t step, const Artifacts& artifacts, Nanoseconds time,
                          std::span<const RenderNode> overlay) {
  const RenderSettings& settings = settings_;
  std::vector<CameraView> views;
  for (auto& c : cameras_) {
    CameraView view;
    view.width = settings.width;
    view.height = settings.height;
    view.fov_deg = c.spec.fov_deg;
    view.shadows = settings.shadows;
    if (c.follow != nullptr) {
      // in the followed robot's frame, turning with its heading only: the picture stays level
      const Pose root = c.follow->root().pose();
      const Vec3 forward = root.orientation * Vec3::UnitX();
      const Pose base{root.position, Quat(Eigen::AngleAxisd(std::atan2(forward.y(), forward.x()), Vec3::UnitZ()))};
      view.pose = lookAt(base.transformPoint(c.spec.position), base.transformPoint(c.spec.look_at));
    } else {
      if (c.spec.frame_scene) {
        // framing every place the robots have been: it widens as they spread, and never jumps back
        const Eigen::AlignedBox3d now = robotsBox(artifacts);
        if (!c.seen.contains(now)) {
          c.seen.extend(now);
          frameBox(c.spec, c.seen, static_cast<double>(settings.width) / settings.height);
        }
      }
      view.pose = lookAt(c.spec.position, c.spec.look_at);
    }
    views.push_back(view);
  }
  try {
    const Nanoseconds stamp = time >= 0 ? time : (step + 1) * timestep_;
    if (overlay.empty()) {
      worker_->submit(items_, std::move(views), stamp);
    } else {
      std::vector<RenderNode> all = items_;
      all.insert(all.end(), overlay.begin(), overlay.end());
      worker_->submit(all, std::move(views), stamp);
    }
  } catch (const std::exception& e) {
    throw StepError("", "render", step, std::string("drawing or writing frames: ") + e.what());
  }
  ++frames_;
}

}  // namespace ssx::detail
