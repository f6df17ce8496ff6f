#pragma once
// checkParameters on part of a parameter set: what the loader runs for a swarm's members once the
// first member's full check found nothing.
#include <ssx/parameters.hpp>

#include <span>
#include <string>
#include <vector>

namespace ssx::detail {

// checkParameters, restricted to the declarations and attributes named in `only` (all of them when
// it is null). Attaches every declaration to `params` all the same.
std::vector<Diagnostic> checkParametersNamed(std::span<const ssx_plugin_param> declarations, Descriptor& params,
                                             const PluginContext& context, const std::string& what,
                                             const std::vector<std::string>* only);

}  // namespace ssx::detail
