// libFuzzer target for the scene and artifact parser (built with -DSSX_FUZZ=ON and clang).
//
// An input is a scene, optionally followed by a line "----" and an artifact file. The artifact is
// written to a scratch directory as a.xml, next to copies of no other files, and the scene is
// loaded with that directory as its base, so `<type name="a" file="a.xml"/>` reaches the
// artifact parser. Loading must either succeed or throw SceneError: anything else (a crash, a
// sanitizer report, another exception) is a finding.
#include <ssx/ssx.hpp>

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace {

std::filesystem::path scratch() {
  static const std::filesystem::path dir = [] {
    char pattern[] = "/tmp/ssx_fuzz_XXXXXX";
    const char* made = mkdtemp(pattern);
    if (made == nullptr) std::abort();
    return std::filesystem::path(made);
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const auto split = input.find("\n----\n");
  const std::string_view scene = input.substr(0, split);
  const std::string_view artifact = split == std::string_view::npos ? std::string_view() : input.substr(split + 6);
  {
    std::ofstream out(scratch() / "a.xml", std::ios::binary | std::ios::trunc);
    out.write(artifact.data(), static_cast<std::streamsize>(artifact.size()));
  }
  ssx::SceneOptions options;
  options.search_installed_plugins = true;  // the built-in plugins: their configure is not run, their loading is
  try {
    ssx::Scene loaded = ssx::loadSceneFromString(scene, "fuzz.xml", scratch(), options);
    (void)loaded;
  } catch (const ssx::SceneError&) {
    // the expected way to refuse bad input
  }
  return 0;
}
