// A quadrotor with a flight controller of one's own: the `pd_quadrotor` driver keeps ssx's vehicle
// (rotors, motors, battery), wind and references (ssx::quadrotor, installed with ssx) and swaps the
// TeleKyb cascade for a short geometric controller on SO(3) (Lee, Leok and McClamroch 2010) that
// reads the ground truth and writes rotor speeds. It takes commands at the position, velocity and
// rotors levels; attitude and rates commands are refused (CommandInterface::refusal says so).
#include <ssx/quadrotor/controller.hpp>
#include <ssx/quadrotor/effects.hpp>
#include <ssx/quadrotor/references.hpp>
#include <ssx/quadrotor/vehicle.hpp>
#include <ssx/ssx.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace {

using namespace ssx;
using namespace ssx::quadrotor;

constexpr ssx_plugin_param kPdParameters[] = {
    param::real("kp", "6", "1/s^2", param::nonNegative(), "position gain"),
    param::real("kd", "4", "1/s", param::nonNegative(), "velocity gain"),
    param::real("kr", "60", "1/s^2", param::positive(), "attitude gain"),
    param::real("kw", "12", "1/s", param::positive(), "body rate gain"),
};

// The controller: position (or velocity) error to a force, the force's direction to an attitude,
// the attitude error to a torque, force and torque to rotor speeds through the allocation.
class GeometricController final : public FlightController {
 public:
  void configure(const Descriptor& params, const std::vector<Rotor>& rotors, const RotorParams& rp, double mass,
                 const Mat3& inertia, double gravity) {
    kp_ = params.get<double>("kp");
    kd_ = params.get<double>("kd");
    kr_ = params.get<double>("kr");
    kw_ = params.get<double>("kw");
    mass_ = mass;
    inertia_ = inertia;
    gravity_ = gravity;
    allocation_inverse_ = Allocation(rotors, rp).inverse();
    max_speed_ = rp.max_rotor_speed;
    count_ = rotors.size();
  }
  bool accepts(CommandLevel level) const override {
    return level == CommandLevel::Position || level == CommandLevel::Velocity || level == CommandLevel::Rotors;
  }
  CommandLevel level() const override { return level_; }
  void setCommand(const Command& command, const Vec3&) override {
    level_ = command.level;
    if (level_ == CommandLevel::Velocity) {
      velocity_ = command.velocity;
      yaw_rate_ = command.yaw_rate;
    }
    if (level_ == CommandLevel::Rotors) std::copy(command.rotor_speeds.begin(), command.rotor_speeds.end(), rotors_.begin());
  }
  Setpoint currentSetpoint() const override { return current_; }

  void step(std::int64_t, double t, FlightInputs& in, std::span<double> speeds) override {
    if (level_ == CommandLevel::Rotors) {
      std::copy_n(rotors_.begin(), count_, speeds.begin());
      return;
    }
    Pose pose;
    Vec3 velocity;
    in.position(pose, velocity);
    const double dt = t - last_t_;
    last_t_ = t;
    const Mat3 R = pose.orientation.toRotationMatrix();
    const double yaw_now = std::atan2(R(1, 0), R(0, 0));
    if (level_ == CommandLevel::Position) {
      current_ = in.reference(t, dt);
      if (!in.holdsHeading()) current_.yaw = yaw_now + current_.yaw_rate * dt;
    } else {  // velocity: no position error, the heading turns at the commanded rate
      current_ = Setpoint{pose.position, velocity_, Vec3::Zero(), yaw_now + yaw_rate_ * dt, yaw_rate_};
    }
    // the force: feed-forward plus PD, plus the weight
    const Vec3 a = current_.acceleration + kd_ * (current_.velocity - velocity) + kp_ * (current_.position - pose.position);
    const Vec3 force = mass_ * (a + Vec3(0, 0, gravity_));
    const double thrust = std::max(0.0, force.dot(R.col(2)));
    // the attitude that points the thrust along the force with the wanted heading
    const Vec3 b3 = force.norm() > 1e-9 ? Vec3(force.normalized()) : Vec3(Vec3::UnitZ());
    const Vec3 heading(std::cos(current_.yaw), std::sin(current_.yaw), 0);
    const Vec3 b2 = b3.cross(heading).normalized();
    Mat3 Rd;
    Rd.col(0) = b2.cross(b3);
    Rd.col(1) = b2;
    Rd.col(2) = b3;
    const Mat3 E = 0.5 * (Rd.transpose() * R - R.transpose() * Rd);
    const Vec3 e_r(E(2, 1), E(0, 2), E(1, 0));
    const Vec3 w = in.bodyRates();
    const Vec3 alpha = -kr_ * e_r - kw_ * w;
    // torque and thrust to squared rotor speeds
    Eigen::Vector4d wrench;
    wrench.head<3>() = inertia_ * alpha;
    wrench(3) = thrust;
    const Eigen::VectorXd w2 = allocation_inverse_ * wrench;
    for (std::size_t i = 0; i < count_; ++i)
      speeds[i] = std::sqrt(std::clamp(w2(static_cast<Eigen::Index>(i)), 0.0, max_speed_ * max_speed_));
  }
  void saveState(StateWriter& out) const override {
    out.write(level_);
    out.write(velocity_);
    out.write(yaw_rate_);
    out.write(last_t_);
    out.write(rotors_);
  }
  void loadState(StateReader& in) override {
    in.read(level_);
    if (!accepts(level_)) throw StateError("pd_quadrotor: the saved command level is not one it takes");
    in.read(velocity_);
    in.read(yaw_rate_);
    in.read(last_t_);
    in.read(rotors_);
  }

 private:
  double kp_ = 6, kd_ = 4, kr_ = 60, kw_ = 12, mass_ = 1, gravity_ = 9.81, max_speed_ = 0, last_t_ = 0;
  Mat3 inertia_ = Mat3::Identity();
  Eigen::MatrixXd allocation_inverse_;
  std::size_t count_ = 0;
  CommandLevel level_ = CommandLevel::Position;
  Vec3 velocity_ = Vec3::Zero();
  double yaw_rate_ = 0;
  std::array<double, kMaxRotors> rotors_{};
  Setpoint current_;
};

class PdQuadrotor final : public Driver, public CommandInterface, private FlightInputs {
 public:
  static constexpr const char* kDoc = "ssx's quadrotor vehicle, wind and references with a geometric controller";
  static constexpr auto kParameters =
      param::join(param::part("vehicle", kVehicleParameters), param::part("wind", kWindParameters),
                  param::part("controller (geometric)", kPdParameters), param::part("references", kReferenceParameters));

  void configure(const Descriptor& params, PluginSetup&) override {
    Artifact& a = artifact();
    const VehicleParams vp(params);
    const std::vector<Rotor> rotors = vp.rotorsOf(params, a);
    vehicle_.configure(RotorModel(rotors, vp.rotor), -a.root().poseInBody().position, vp.battery);
    wind_.configure(windParams(params, environment().settings().wind), groundHeight(environment()));
    references_.configure(ReferenceParams(params), params, a, nullptr);
    const MassProperties mass = combinedMass(a.root().spec());
    const double g = -environment().settings().physics.gravity.z();
    controller_.configure(params, rotors, vp.rotor, mass.mass, mass.inertia, g);
  }
  void step(const StepInfo& info) override {
    const double t = toSeconds(info.time), dt = info.periodSeconds();
    const std::size_t n = vehicle_.rotorCount();
    controller_.step(info.step / periodSteps(), t, *this, std::span(speeds_).first(n));
    vehicle_.stepMotors(dt, std::span(speeds_).first(n));
    PhysicNode& body = artifact().root();
    const BodyState& com = environment().bodyState(body.bodyIndex());
    const Vec3 air = wind_.active() ? wind_.air(t, dt, com.pose.position, com.linear_velocity, random()) : Vec3::Zero();
    if (vehicle_.hasBattery()) vehicle_.updateGains(dt, [](std::size_t) { return 1.0; });
    vehicle_.applyWrench(body, body.state(), com, air);
  }
  void saveState(StateWriter& out) const override {
    vehicle_.saveState(out);
    out.write(speeds_);
    controller_.saveState(out);
    references_.saveState(out);
    wind_.saveState(out);
  }
  void loadState(StateReader& in) override {
    vehicle_.loadState(in);
    in.read(speeds_);
    controller_.loadState(in);
    references_.loadState(in);
    wind_.loadState(in);
  }

  bool acceptsCommand(CommandLevel level) const override { return controller_.accepts(level); }
  std::size_t rotorCount() const override { return vehicle_.rotorCount(); }
  void setCommand(const Command& command) override {
    if (const std::string why = refusal(command); !why.empty()) throw std::invalid_argument("pd_quadrotor: " + why);
    if (command.level == CommandLevel::Position) references_.setExternal(command.setpoint);
    controller_.setCommand(command, artifact().state().pose.position);
  }
  CommandLevel commandLevel() const override { return controller_.level(); }
  Setpoint currentSetpoint() const override { return controller_.currentSetpoint(); }

 private:
  Setpoint reference(double t, double dt) override { return references_.at(t, dt); }
  bool holdsHeading() const override { return references_.holdsHeading(); }
  void position(Pose& pose, Vec3& velocity) const override {
    const BodyState s = artifact().state();
    pose = s.pose;
    velocity = s.linear_velocity;
  }
  Vec3 bodyRates() const override {
    const BodyState s = artifact().state();
    return s.pose.orientation.conjugate() * s.angular_velocity;
  }

  Vehicle vehicle_;
  Wind wind_;
  References references_;
  GeometricController controller_;
  std::array<double, kMaxRotors> speeds_{};
};

}  // namespace

SSX_PLUGIN(SSX_DRIVER(PdQuadrotor, "pd_quadrotor"));
