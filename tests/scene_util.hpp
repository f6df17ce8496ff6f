#pragma once
// Helpers for tests that load scene files: where the test data and examples are, the options that
// find the test plugins, and a file read back as lines or as text.
#include <ssx/ssx.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace ssx::test {

inline const std::filesystem::path kData = SSX_TEST_DATA_DIR;
inline const std::filesystem::path kArtifacts = std::filesystem::path(SSX_EXAMPLES_DIR) / "artifacts";

/// Options whose plugin path holds the test plugins (tests/plugins) before the built-in ones.
inline SceneOptions testOptions() {
  SceneOptions o;
  o.plugin_path.emplace_back(SSX_TEST_PLUGIN_DIR);
  return o;
}

inline std::vector<std::string> fileLines(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

inline std::string fileText(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace ssx::test
