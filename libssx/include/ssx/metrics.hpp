#pragma once
/// @file
/// Metrics a plugin publishes for sweeps (`ssx sweep`) and other observers: a plugin (driver,
/// sensor or extension) that implements MetricSource is found with
/// `dynamic_cast<const ssx::MetricSource*>(&plugin)` (the type lives in libssx, so the cast works
/// across plugin libraries).

#include <ssx/export.hpp>

#include <string>
#include <vector>

namespace ssx {

/// One named value, e.g. a formation error in metres.
struct Metric {
  std::string name;   ///< what it is, with its unit where it has one ("formation_error_m")
  double value = 0.0;  ///< its value now
};

/// Implemented by plugins with numbers worth collecting. Called between steps from the thread
/// that steps (never during the parallel phases).
class SSX_EXPORT MetricSource {
 public:
  virtual ~MetricSource();
  /// The names this instance publishes, fixed from configure on (may be empty).
  virtual std::vector<std::string> metricNames() const = 0;
  /// Appends the current value of each name of metricNames(), in that order; NaN when there is
  /// none right now (a formation member that sees nobody), which collectors skip.
  virtual void metrics(std::vector<Metric>& out) const = 0;
};

}  // namespace ssx
