// A good plugin library with three classes of three kinds.
#include <ssx/artifact.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <fstream>

namespace {

// spins its body about z with a constant torque from parameter `torque`
class Spinner final : public ssx::Driver {
 public:
  void configure(const ssx::Descriptor& params) override { torque_ = params.get<double>("torque", 0.1); }
  void step(const ssx::StepInfo&) override { artifact().root().addTorque(ssx::Vec3(0, 0, torque_)); }

 private:
  double torque_ = 0;
};

class Counter final : public ssx::SensorOf<ssx::ClockMeasurement> {
 public:
  void sense(const ssx::StepInfo& info) override {
    output().step = info.step;
    output().stamp = info.time;
  }
};

// writes the file named by `file` (relative: to the working directory) when initialised, so a
// test can tell whether a scene ever started
class Marker final : public ssx::SimulationExtension {
 public:
  void init(ssx::Environment&, const ssx::Descriptor& params) override {
    std::ofstream(params.get<std::string>("file", "marker_ran.txt")) << "initialised\n";
  }
};

}  // namespace

SSX_PLUGIN(SSX_DRIVER(Spinner, "spinner"), SSX_SENSOR(Counter, "counter"), SSX_EXTENSION(Marker, "marker"));
