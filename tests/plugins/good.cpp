// A good plugin library with classes of three kinds.
#include <cstdlib>
#include <ssx/artifact.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <fstream>
#include <string>
#include <stdexcept>

namespace {

// spins its body about z with a constant torque from parameter `torque`
class Spinner final : public ssx::Driver {
 public:
  static constexpr ssx_plugin_param kParameters[] = {
      ssx::param::real("torque", "0.1", "N m", ssx::param::any(), "torque about z"),
  };
  // works its torque out once per torque in a scene (PluginContext::shared), counting how often;
  // a torque above 1000 N m is refused there
  static void validate(const ssx::Descriptor& params, const ssx::PluginContext& context);
  void configure(const ssx::Descriptor& params, ssx::PluginSetup& /*setup*/) override { torque_ = params.get<double>("torque", 0.1); }
  void step(const ssx::StepInfo&) override { artifact().root().addTorque(ssx::Vec3(0, 0, torque_)); }

 private:
  double torque_ = 0;
};

int spinner_checks_made = 0;
void Spinner::validate(const ssx::Descriptor& params, const ssx::PluginContext& context) {
  const std::string text = params.get<std::string>("torque");
  (void)context.shared<double>(text, [&] {
    ++spinner_checks_made;
    const double torque = params.get<double>("torque");
    if (torque > 1000) throw params.errorAt("torque", "torque above 1000 N m");
    return torque;
  });
}

class Counter final : public ssx::SensorOf<ssx::ClockMeasurement> {
 public:
  void sense(const ssx::StepInfo& info) override {
    output().step = info.step;
    output().stamp = info.time;
  }
};

// throws (or, how="abort", takes its process down) at step `at_step` in the artifact named `only`
class Bomb final : public ssx::Driver {
 public:
  static constexpr ssx_plugin_param kParameters[] = {
      ssx::param::integer("at_step", "0", ssx::param::nonNegative(), "step to throw at"),
      ssx::param::text("only", "", "throw only in the artifact of this name (default: every artifact)"),
      ssx::param::choice("how", "throw", "throw abort", "throw an exception, or abort the process"),
  };
  void configure(const ssx::Descriptor& params, ssx::PluginSetup& /*setup*/) override {
    at_step_ = params.get<std::int64_t>("at_step", 0);
    armed_ = params.get<std::string>("only", artifact().name()) == artifact().name();
    abort_ = params.get<std::string>("how", "throw") == "abort";
  }
  void step(const ssx::StepInfo& info) override {
    if (!armed_ || info.step != at_step_) return;
    if (abort_) std::abort();
    throw std::runtime_error("exploded as asked");
  }

 private:
  std::int64_t at_step_ = 0;
  bool armed_ = false;
  bool abort_ = false;
};

// writes the file named by `file` (relative: to the working directory) when initialised, so a
// test can tell whether a scene ever started
class Marker final : public ssx::SimulationExtension {
 public:
  static constexpr ssx_plugin_param kParameters[] = {
      ssx::param::text("file", "marker_ran.txt", "file to write when initialised"),
  };
  void init(ssx::Environment&, const ssx::Descriptor& params) override {
    std::ofstream(params.get<std::string>("file", "marker_ran.txt")) << "initialised\n";
  }
};

// counts its live instances, for tests of how the loader builds and destroys them
int live_tallies = 0;
class Tally final : public ssx::Driver {
 public:
  Tally() { ++live_tallies; }
  ~Tally() override { --live_tallies; }
  void step(const ssx::StepInfo&) override {}

 private:
  std::string held_ = std::string(100, 'x');  // on the heap: a leak if the destructor never runs
};

}  // namespace

extern "C" __attribute__((visibility("default"))) int ssx_test_live_tallies() { return live_tallies; }
extern "C" __attribute__((visibility("default"))) int ssx_test_spinner_checks() { return spinner_checks_made; }

SSX_PLUGIN(SSX_DRIVER(Spinner, "spinner"), SSX_SENSOR(Counter, "counter"), SSX_EXTENSION(Marker, "marker"),
           SSX_DRIVER(Bomb, "bomb"), SSX_DRIVER(Tally, "tally"));
