// Every input in tests/data/fuzz/<target>/ (seeds, and whatever a fuzzer once found) runs through
// the same code as its libFuzzer target and must be refused or run cleanly. In the sanitizer build
// of CI this is where a fixed finding would come back.
#include "fuzz_inputs.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

int replay(const std::string& target, void (*run)(std::span<const std::uint8_t>)) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(SSX_TEST_DATA_DIR) / "fuzz" / target)) {
    if (entry.path().filename() == "README.md") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    INFO(target << ": " << entry.path().filename().string());
    CHECK_NOTHROW(run({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()}));
    ++files;
  }
  return files;
}

}  // namespace

TEST_CASE("inputs the fuzzers found or started from are refused or run cleanly: scenes", "[fuzz]") {
  CHECK(replay("scene", ssx::fuzz::sceneInput) >= 1);
}

TEST_CASE("inputs the fuzzers found or started from are refused or run cleanly: artifacts", "[fuzz]") {
  CHECK(replay("artifact", ssx::fuzz::artifactInput) >= 1);
}

TEST_CASE("inputs the fuzzers found or started from are refused or run cleanly: robots (URDF)", "[fuzz]") {
  CHECK(replay("robot", ssx::fuzz::robotInput) >= 3);
}

TEST_CASE("inputs the fuzzers found or started from are refused or run cleanly: parameters", "[fuzz]") {
  CHECK(replay("parameter", ssx::fuzz::parameterInput) >= 1);
}

TEST_CASE("inputs the fuzzers found or started from are refused or run cleanly: saved states", "[fuzz]") {
  CHECK(replay("state", ssx::fuzz::stateInput) >= 1);
}

TEST_CASE("inputs the fuzzers found or started from are refused or run cleanly: recordings", "[fuzz]") {
  CHECK(replay("recording", ssx::fuzz::recordingInput) >= 1);
}

TEST_CASE("inputs the fuzzers found or started from are refused or run cleanly: command lines", "[fuzz]") {
  CHECK(replay("command_line", ssx::fuzz::commandLineInput) >= 1);
}
