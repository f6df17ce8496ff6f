// orbit: a driver that flies a rigid body around a horizontal circle at constant speed, with a
// PD law on the position error to the moving reference and feed-forward of its acceleration.
//
// Parameters: center "x y z" (m), radius (m, default 1), orbit_period (s, default 8), kp, kd.
#include <ssx/ssx.hpp>

#include <cmath>
#include <numbers>

namespace {

class OrbitDriver final : public ssx::Driver {
 public:
  void configure(const ssx::Descriptor& params) override {
    center_ = params.get<ssx::Vec3>("center", artifact().placement().position);
    radius_ = params.getPositive("radius", 1.0);
    omega_ = 2 * std::numbers::pi / params.getPositive("orbit_period", 8.0);
    kp_ = params.getPositive("kp", 16.0);
    kd_ = params.getPositive("kd", 8.0);
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
