// A manifest built against another ssx: refused by its build tag.
#include <ssx/plugin_abi.hpp>

namespace {
void* neverCalled(char*, std::size_t) noexcept { __builtin_trap(); }
void neverDestroyed(void*) noexcept { __builtin_trap(); }
constexpr ssx_plugin_class kClasses[] = {{SSX_PLUGIN_DRIVER, "old", &neverCalled, &neverDestroyed}};
}  // namespace

extern "C" __attribute__((visibility("default"))) const ssx_plugin_manifest ssx_plugin_manifest_v1;
extern "C" __attribute__((visibility("default"))) const ssx_plugin_manifest ssx_plugin_manifest_v1 = {
    SSX_PLUGIN_ABI_VERSION, sizeof(ssx_plugin_manifest), sizeof(ssx_plugin_class), 1, "ssx 0.0; libc++", kClasses};
