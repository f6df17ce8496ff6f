// camera: RGB and depth images from a camera mounted on a node (ssx::CameraMeasurement).
//
// The image of a step is drawn by the environment's render engine in that step's snapshot phase,
// on the thread that steps (OpenGL is used from one thread only), from that step's snapshot; the
// sensor hands it out in the sensors phase of the same step. Needs a render engine that draws
// pixels (<render engine="osmesa"/> or --render osmesa); the sensor's period sets its rate.
//
// Parameters: kParameters below, or `ssx plugins --params camera`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <utility>

namespace ssx::plugins {

class CameraSensor final : public SensorOf<CameraMeasurement> {
 public:
  static constexpr const char* kDoc = "RGB and depth images from a camera mounted on a node (needs osmesa)";
  static constexpr ssx_plugin_param kParameters[] = {
      param::text("node", "", "physic node it is mounted on (default: the first root)"),
      param::vec3("xyz", "0 0 0", "m", param::any(), "mount position on that node"),
      param::vec3("rpy", "0 0 0", "rad", param::any(),
                  "mount roll, pitch, yaw on that node; the camera looks along its +x with +z up"),
      param::integer("width", "320", param::between(1, kMaxImageSide), "image width, pixels"),
      param::integer("height", "240", param::between(1, kMaxImageSide), "image height, pixels"),
      param::real("fov_deg", "60", "deg", param::positive() & param::below(180), "horizontal field of view"),
      param::real("near", "0.05", "m", param::positive(), "near clipping distance"),
      param::real("far", "100", "m", param::positive(), "far clipping distance; depth beyond it reads +infinity"),
      param::flag("depth", "true", "also deliver the depth image"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    (void)context.artifact->nodeFromParameter(params);
    if (params.get<double>("far") <= params.get<double>("near"))
      throw params.errorAt("far", "far must be beyond near");
  }

  void configure(const Descriptor& params, PluginSetup& setup) override {
    node_ = &artifact().nodeFromParameter(params);
    mount_.position = params.get<Vec3>("xyz");
    const Vec3 rpy = params.get<Vec3>("rpy");
    mount_.orientation = Quat(Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                              Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()));
    lens_.width = static_cast<int>(params.get<std::int64_t>("width"));
    lens_.height = static_cast<int>(params.get<std::int64_t>("height"));
    lens_.fov_deg = params.get<double>("fov_deg");
    lens_.near = params.get<double>("near");
    lens_.far = params.get<double>("far");
    lens_.depth = params.get<bool>("depth");
    setup.addCameraRequest(
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
