#include <ssx/metrics.hpp>

namespace ssx {

MetricSource::~MetricSource() = default;

}  // namespace ssx
