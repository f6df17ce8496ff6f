#include "render/scene_cameras.hpp"

#include "render/frame_output.hpp"
#include "render/frame_worker.hpp"

#include <ssx/error.hpp>

#include <algorithm>
#include <cmath>
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

SceneCameras::SceneCameras() = default;
SceneCameras::~SceneCameras() = default;

void SceneCameras::start(const RenderSettings& r, Nanoseconds timestep, const RenderEngine& renderer,
                         const Artifacts& artifacts, const Log& warn) {
  timestep_ = timestep;
  // render roots follow their physic nodes, looked up once
  follow_.clear();
  for (const auto& a : artifacts) {
    auto& follow = follow_.emplace_back();
    for (const auto& root : a->renderRoots()) follow.push_back(root->follow.empty() ? nullptr : a->node(root->follow));
  }
  if (r.cameras.empty()) return;
  if (!renderer.drawsPixels()) {
    std::string names;
    for (const auto& c : r.cameras) names += (names.empty() ? "'" : ", '") + c.name + "'";
    warn("render engine '" + renderer.name() + "' draws no pixels: camera " + names +
         " gets no frames (choose engine=\"osmesa\" in <render> or --render osmesa)");
    return;
  }
  for (const CameraSpec& spec : r.cameras) {
    Camera c;
    c.spec = spec;
    if (!spec.follow.empty()) {
      for (const auto& a : artifacts)
        if (a->name() == spec.follow) c.follow = a.get();
      if (c.follow == nullptr || c.follow->rootCount() == 0)
        throw ConfigError({}, "camera '" + spec.name + "' follows '" + spec.follow +
                                  "', which is no artifact with a physic root");
    }
    if (spec.frame_scene) {
      c.seen = robotsBox(artifacts);
      frameBox(c.spec, c.seen, static_cast<double>(r.width) / r.height);
    }
    cameras_.push_back(std::move(c));
  }
  const double fps = 1.0 / (static_cast<double>(r.period_steps) * toSeconds(timestep));
  std::vector<std::unique_ptr<FrameOutput>> outputs;
  for (const auto& c : cameras_) outputs.push_back(std::make_unique<FrameOutput>(c.spec, fps, warn));
  worker_ = std::make_unique<FrameWorker>(r, std::move(outputs));
}

void SceneCameras::finish(const Log& error) {
  if (worker_) {
    try {
      worker_->finish();
    } catch (const std::exception& e) {
      error(std::string("frames: ") + e.what());
    }
    worker_.reset();
  }
  cameras_.clear();
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

void SceneCameras::renderRequests(std::int64_t step, RenderEngine& renderer, const Color& background,
                                  const Artifacts& artifacts) {
  CameraView view;
  for (auto& r : requests_) {
    try {
      view = CameraView{};
      if (!r.due(step, view)) continue;
      sync(step + 1, artifacts);
      renderer.renderView(view, items_, background, *r.target);
    } catch (const std::exception& e) {
      throw StepError("", r.owner, step, std::string("camera image: ") + e.what());
    }
  }
}

void SceneCameras::drawFrame(std::int64_t step, const RenderSettings& settings, const Artifacts& artifacts,
                             Nanoseconds time, std::span<const RenderNode> overlay) {
  sync(step + 1, artifacts);  // also without cameras: renderNodes() serves viewers outside ssx
  if (!worker_) return;
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
