// A driver whose constructor throws.
#include <ssx/plugin_abi.hpp>

#include <stdexcept>

namespace {
class Fragile final : public ssx::Driver {
 public:
  Fragile() { throw std::runtime_error("calibration file not found"); }
  void step(const ssx::StepInfo&) override {}
};
}  // namespace

SSX_PLUGIN(SSX_DRIVER(Fragile, "fragile"));
