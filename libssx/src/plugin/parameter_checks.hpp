#pragma once
// checkParameters on part of a parameter set: what the loader runs for a swarm's members once the
// first member's full check found nothing.
#include <ssx/parameters.hpp>

#include <algorithm>
#include <span>
#include <string_view>
#include <string>
#include <vector>

namespace ssx::detail {

// whether `declarations` has one named `name`
inline bool declares(std::span<const ssx_plugin_param> declarations, std::string_view name) {
  return std::any_of(declarations.begin(), declarations.end(),
                     [&](const ssx_plugin_param& d) { return name == d.name; });
}

// checkParameters, restricted to the declarations and attributes named in `only` (all of them when
// it is null). Attaches every declaration to `params` all the same.
std::vector<Diagnostic> checkParametersNamed(std::span<const ssx_plugin_param> declarations, Descriptor& params,
                                             const PluginContext& context, const std::string& what,
                                             const std::vector<std::string>* only);

}  // namespace ssx::detail
