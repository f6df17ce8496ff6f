// A class whose create function returns null without saying why.
#include <ssx/plugin_abi.hpp>

namespace {
void* returnsNull(char*, std::size_t) noexcept { return nullptr; }
void destroyNothing(void*) noexcept {}
constexpr ssx_plugin_class kClasses[] = {{SSX_PLUGIN_SENSOR, "ghost", &returnsNull, &destroyNothing}};
}  // namespace

extern "C" __attribute__((visibility("default"))) const ssx_plugin_manifest ssx_plugin_manifest_v1;
extern "C" __attribute__((visibility("default"))) const ssx_plugin_manifest ssx_plugin_manifest_v1 = {
    SSX_PLUGIN_ABI_VERSION, sizeof(ssx_plugin_manifest), sizeof(ssx_plugin_class), 1, SSX_PLUGIN_BUILD_TAG, kClasses};
