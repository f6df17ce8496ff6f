// camera: RGB and depth images from a camera mounted on a node (ssx::CameraMeasurement).
//
// The image of a step is drawn by the environment's render engine in that step's snapshot phase,
// on the thread that steps (OpenGL is used from one thread only), from that step's snapshot; the
// sensor hands it out in the sensors phase of the same step. Needs a render engine that draws
// pixels (<render engine="osmesa"/> or --render osmesa); the sensor's period sets its rate.
//
// Parameters:
//   node      physic node it is mounted on (default: the first root)
//   xyz, rpy  mount pose on that node; the camera looks along its +x with +z up (default: none)
//   width, height  pixels (default 320 x 240)
//   fov_deg   horizontal field of view (default 60)
//   near, far clipping distances, m (default 0.05, 100); depth beyond far reads +infinity
//   depth     also deliver the depth image (default true)
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <utility>

namespace ssx::plugins {

class CameraSensor final : public SensorOf<CameraMeasurement> {
 public:
  void configure(const Descriptor& params) override {
    node_ = &artifact().nodeFromParameter(params);
    mount_.position = params.get<Vec3>("xyz", Vec3::Zero());
    const Vec3 rpy = params.get<Vec3>("rpy", Vec3::Zero());
    mount_.orientation = Quat(Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                              Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()));
    lens_.width = static_cast<int>(params.get<std::int64_t>("width", 320));
    lens_.height = static_cast<int>(params.get<std::int64_t>("height", 240));
    if (lens_.width < 1 || lens_.width > 8192 || lens_.height < 1 || lens_.height > 8192)
      throw params.error("width and height must be in 1..8192");
    lens_.fov_deg = params.get<double>("fov_deg", 60.0);
    if (!(lens_.fov_deg > 0 && lens_.fov_deg < 180)) throw params.error(*params.find("fov_deg"), "fov_deg must be in (0, 180)");
    lens_.near = params.getPositive("near", 0.05);
    lens_.far = params.getPositive("far", 100.0);
    if (lens_.far <= lens_.near) throw params.error("far must be beyond near");
    lens_.depth = params.get<bool>("depth", true);
    environment().addCameraRequest(
        "sensor 'camera' of artifact '" + artifact().name() + "'",
        [this](std::int64_t step, CameraView& view) {
          if (step % periodSteps() != 0) return false;
          view = lens_;
          view.pose = node_->pose() * mount_;
          drawn_view_ = view;
          return true;
        },
        drawn_);
  }

  void sense(const StepInfo& info) override {
    CameraMeasurement& m = output();
    m.stamp = info.time;
    // the drawn image becomes the measurement; the old one's memory is drawn into next time
    std::swap(m.image, drawn_);
    m.view = drawn_view_;
  }

 private:
  const PhysicNode* node_ = nullptr;
  Pose mount_;
  CameraView lens_;
  CameraView drawn_view_;
  Image drawn_;  // written in the snapshot phase, handed out in the sensors phase
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::CameraSensor, "camera"));
