#pragma once
// `ssx plugins`: the plugin libraries on the search path, each inspected in a child process.
#include <string>
#include <vector>

namespace ssx::cli {

/// What one library reports (`ssx plugins --inspect FILE [--params CLASS]`, run as a child).
int inspectOne(const std::string& file, const std::string& params_of);
/// `ssx plugins [--params CLASS]`.
int commandPlugins(const std::vector<std::string>& plugin_path, const std::string& params_of);

}  // namespace ssx::cli
