#pragma once
// What the ssx command's subcommands share: exit statuses, the plugin search path, lists.
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace ssx::cli {

constexpr int kExitRunFailure = 1;
constexpr int kExitBadInput = 2;

// --plugin-path first, then SSX_PLUGIN_PATH (colon-separated), read here and nowhere else
inline std::vector<std::filesystem::path> pluginPath(const std::vector<std::string>& from_args) {
  std::vector<std::filesystem::path> out(from_args.begin(), from_args.end());
  if (const char* env = std::getenv("SSX_PLUGIN_PATH")) {
    std::stringstream in(env);
    std::string dir;
    while (std::getline(in, dir, ':'))
      if (!dir.empty()) out.emplace_back(dir);
  }
  return out;
}

inline std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace ssx::cli
