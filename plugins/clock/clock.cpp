// clock: a sensor that reports simulated time (ssx::ClockMeasurement).
//
// Parameters: none besides `period` (steps).
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

namespace ssx::plugins {

class ClockSensor final : public SensorOf<ClockMeasurement> {
 public:
  static constexpr const char* kDoc = "simulated time, as a measurement";
  void saveState(StateWriter& out) const override { save(out, value()); }
  void loadState(StateReader& in) override { load(in, output()); }

  void sense(const StepInfo& info) override {
    output().stamp = info.time;
    output().step = info.step;
    output().seconds = toSeconds(info.time);
  }
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::ClockSensor, "clock"));
