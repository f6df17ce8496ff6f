#pragma once
// What the ssx command's subcommands share: exit statuses, the plugin search path, lists.
#include <ssx/ssx.hpp>

#include <cstdint>
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

// --max-input-mb: the largest file a command reads as input, in MiB (default: the library's 64)
constexpr double kDefaultMaxInputMb = 64.0;
constexpr double kMostMaxInputMb = 1 << 20;  // 1 TiB: beyond it, a file is no scene
inline std::uintmax_t maxInputBytes(double mb) { return static_cast<std::uintmax_t>(mb * (1 << 20)); }

// where a scene's relative outputs go: --out, else ssx-out/<scene's name>/
inline std::filesystem::path outputDirectory(const std::string& scene, const std::string& out) {
  return out.empty() ? std::filesystem::path("ssx-out") / std::filesystem::path(scene).stem() : std::filesystem::path(out);
}

inline std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// --view: the viewer extension, as <extension plugin="viewer"/> adds it (it listens when the
// environment starts); with `recording`, playing that recording instead of the run. Attached as an
// observer: not part of the run's saved states, so that a recording of a run with a view
// re-simulates without one. `wait`: the run holds after its first step until a page connects.
inline void addViewer(ssx::Environment& env, int port, const std::string& bind, const std::string& recording = {},
                      bool wait = false) {
  ssx::Descriptor params("viewer", {"--view", 0});
  params.set("port", static_cast<std::int64_t>(port)).set("bind", bind).set("wait", wait);
  if (!recording.empty()) params.set("recording", recording);
  env.attachExtension("viewer", env.classLoader().createExtension("viewer", "viewer"), params);
}

// --foxglove: the foxglove extension, as <extension plugin="foxglove"/> adds it (it listens when the
// environment starts); an observer, as the viewer
inline void addFoxglove(ssx::Environment& env, int port, const std::string& bind) {
  ssx::Descriptor params("foxglove", {"--foxglove", 0});
  params.set("port", static_cast<std::int64_t>(port)).set("bind", bind);
  env.attachExtension("foxglove", env.classLoader().createExtension("foxglove", "foxglove"), params);
}

}  // namespace ssx::cli
