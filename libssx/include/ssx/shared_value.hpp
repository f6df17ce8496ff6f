#pragma once
/// @file
/// What PluginSetup::shared (while an environment starts) and PluginContext::shared (while a scene
/// loads) have in common: a value made once and handed to every later asker.

#include <memory>
#include <type_traits>

namespace ssx::detail {

/// The value held in `slot`, else `make()`'s result (a T, or a pointer to one), then kept in
/// `slot`. Without a slot (null) every call makes its own; a `make` that throws keeps nothing.
template <class T, class Make>
std::shared_ptr<const T> sharedValue(std::shared_ptr<const void>* slot, Make&& make) {
  if (slot != nullptr && *slot) return std::static_pointer_cast<const T>(*slot);
  std::shared_ptr<const T> value;
  if constexpr (std::is_convertible_v<std::invoke_result_t<Make>, std::shared_ptr<const T>>)
    value = make();
  else
    value = std::make_shared<const T>(make());
  if (slot != nullptr) *slot = value;
  return value;
}

}  // namespace ssx::detail
