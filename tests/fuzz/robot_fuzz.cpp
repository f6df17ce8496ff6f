// libFuzzer target: see robotInput in fuzz_inputs.hpp (built with -DSSX_FUZZ=ON and clang).
#include "fuzz_inputs.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ssx::fuzz::robotInput({data, size});
  return 0;
}
