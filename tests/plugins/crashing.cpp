// A library that crashes while it is being loaded, in a static initialiser: before any check can
// run. `ssx plugins` must report it and go on (it inspects each library in a child process).
// Kept apart from the other test plugins (tests/plugins_crashing), so that nothing else loads it.
#include <ssx/plugin_abi.hpp>

#include <csignal>

namespace {
const int crash = [] {
  std::raise(SIGSEGV);
  return 0;
}();

class Never final : public ssx::Driver {
 public:
  void step(const ssx::StepInfo&) override {}
};
}  // namespace

SSX_PLUGIN(SSX_DRIVER(Never, "never"));
