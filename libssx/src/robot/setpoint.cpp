#include <ssx/setpoint.hpp>

namespace ssx {

SetpointInterface::~SetpointInterface() = default;

}  // namespace ssx
