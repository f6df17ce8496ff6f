#include <ssx/artifact.hpp>
#include <ssx/plugin.hpp>

namespace ssx {

Plugin::~Plugin() = default;
void Plugin::configure(const Descriptor&) {}
void Plugin::destroy() {}
void Plugin::saveState(StateWriter&) const {}
void Plugin::loadState(StateReader&) {}

Measurement::~Measurement() = default;

SimulationExtension::~SimulationExtension() = default;
void SimulationExtension::init(Environment&, const Descriptor&) {}
void SimulationExtension::beforeStep(Environment&) {}
void SimulationExtension::afterStep(Environment&) {}
void SimulationExtension::shutdown(Environment&) {}
void SimulationExtension::saveState(StateWriter&) const {}
void SimulationExtension::loadState(StateReader&) {}

}  // namespace ssx

#include <ssx/measurements.hpp>

namespace ssx {
ClockMeasurement::~ClockMeasurement() = default;
PoseMeasurement::~PoseMeasurement() = default;
}  // namespace ssx

namespace ssx {
ImuMeasurement::~ImuMeasurement() = default;
}  // namespace ssx

#include <ssx/setpoint.hpp>

namespace ssx {
SetpointInterface::~SetpointInterface() = default;
}  // namespace ssx

namespace ssx {
RangeMeasurement::~RangeMeasurement() = default;
CameraMeasurement::~CameraMeasurement() = default;
}  // namespace ssx
