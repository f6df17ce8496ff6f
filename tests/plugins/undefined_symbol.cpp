// A plugin that needs a function nobody defines: dlopen with RTLD_NOW must fail at load.
#include <ssx/plugin_abi.hpp>

namespace missing {
double solveRiccati(int iterations);  // declared, never defined
}

namespace {
class Lqr final : public ssx::Driver {
 public:
  void step(const ssx::StepInfo&) override { gain_ = missing::solveRiccati(10); }

 private:
  double gain_ = 0;
};
}  // namespace

SSX_PLUGIN(SSX_DRIVER(Lqr, "lqr"));
