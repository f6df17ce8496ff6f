// orbit: a driver that flies a rigid body around a horizontal circle at constant speed, with a
// PD law on the position error to the moving reference and feed-forward of its acceleration.
//
// Its parameters are declared in kParameters: the scene loader checks every value against them
// before anything runs, and `ssx plugins --params orbit` lists them.
#include <ssx/ssx.hpp>

#include <cmath>
#include <numbers>

namespace {

class OrbitDriver final : public ssx::Driver {
 public:
  static constexpr const char* kDoc = "flies a rigid body around a horizontal circle at constant speed";
  static constexpr ssx_plugin_param kParameters[] = {
      ssx::param::vec3("center", "", "m", ssx::param::any(), "centre of the circle (default: where it starts)"),
      ssx::param::real("radius", "1", "m", ssx::param::positive(), "radius of the circle"),
      ssx::param::real("orbit_period", "8", "s", ssx::param::positive(), "time for one lap"),
      ssx::param::real("kp", "16", "1/s^2", ssx::param::positive(), "position gain"),
      ssx::param::real("kd", "8", "1/s", ssx::param::positive(), "velocity gain"),
  };

  void configure(const ssx::Descriptor& params, ssx::PluginSetup& /*setup*/) override {
    center_ = params.get<ssx::Vec3>("center", artifact().placement().position);
    radius_ = params.get<double>("radius");
    omega_ = 2 * std::numbers::pi / params.get<double>("orbit_period");
    kp_ = params.get<double>("kp");
    kd_ = params.get<double>("kd");
    mass_ = ssx::combinedMass(artifact().root().spec()).mass;
    gravity_ = environment().settings().physics.gravity;
  }

  void step(const ssx::StepInfo& info) override {
    const double t = info.periodSeconds() * static_cast<double>(info.step / periodSteps());
    const double a = omega_ * t;
    const ssx::Vec3 p_ref = center_ + radius_ * ssx::Vec3(std::cos(a), std::sin(a), 0);
    const ssx::Vec3 v_ref = radius_ * omega_ * ssx::Vec3(-std::sin(a), std::cos(a), 0);
    const ssx::Vec3 a_ref = -omega_ * omega_ * (p_ref - center_);
    const ssx::BodyState s = artifact().state();
    const ssx::Vec3 accel = a_ref + kp_ * (p_ref - s.pose.position) + kd_ * (v_ref - s.linear_velocity);
    artifact().root().addForce(mass_ * (accel - gravity_));
  }

 private:
  ssx::Vec3 center_, gravity_;
  double radius_ = 1, omega_ = 1, kp_ = 16, kd_ = 8, mass_ = 1;
};

}  // namespace

SSX_PLUGIN(SSX_DRIVER(OrbitDriver, "orbit"));
