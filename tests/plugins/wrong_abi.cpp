// A manifest from a future ABI: the loader must refuse it without calling anything.
#include <ssx/plugin_abi.hpp>

namespace {
void* neverCalled(char*, std::size_t) noexcept { __builtin_trap(); }
void neverDestroyed(void*) noexcept { __builtin_trap(); }
constexpr ssx_plugin_class kClasses[] = {{SSX_PLUGIN_DRIVER, "future", &neverCalled, &neverDestroyed}};
}  // namespace

extern "C" __attribute__((visibility("default"))) const ssx_plugin_manifest ssx_plugin_manifest_v1;
extern "C" __attribute__((visibility("default"))) const ssx_plugin_manifest ssx_plugin_manifest_v1 = {
    999, sizeof(ssx_plugin_manifest), sizeof(ssx_plugin_class), 1, SSX_PLUGIN_BUILD_TAG, kClasses};
