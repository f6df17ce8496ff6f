#pragma once
// A measurement's JSON (ssx::measurementJson) appended to a string the caller keeps: the channels
// that write every robot's measurements in one message (/ssx/sensors) write them in place.

#include <ssx/measurements.hpp>

#include <string>

namespace ssx {
class Environment;
}

namespace ssx::detail {

/// Appends `m` as measurementJson writes it; false (nothing appended) for a kind without one.
bool appendMeasurementJson(std::string& out, const Measurement& m, const Environment& env);

}  // namespace ssx::detail
