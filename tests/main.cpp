// The test runner. ctest runs every test case in its own process (catch_discover_tests); each
// process works in a fresh directory of its own under the system's temporary directory (TMPDIR),
// so that tests writing files (CSV logs, frames, saved states, scenes made on the fly) never meet,
// however many ctest runs at once, and never write where they were started from (a source tree).
// The directory is removed when every test in the process passed, and kept for inspection, with a
// line saying where, when one failed and left files.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

int main(int argc, char* argv[]) {
  namespace fs = std::filesystem;
  const fs::path parent = fs::current_path();
  std::error_code no_temp;
  fs::path temp = fs::temp_directory_path(no_temp);
  if (no_temp) temp = "/tmp";
  std::string pattern = (temp / "ssx_test_XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr || chdir(pattern.c_str()) != 0) {
    std::perror("ssx_tests: cannot make a working directory of its own");
    return 2;
  }
  const int failed = Catch::Session().run(argc, argv);
  std::error_code ignored;
  fs::current_path(parent, ignored);
  if (failed == 0)
    fs::remove_all(pattern, ignored);
  else if (!fs::remove(pattern, ignored) && fs::exists(pattern, ignored))  // removed only when empty
    std::fprintf(stderr, "ssx_tests: the failed test's files are kept in %s\n", pattern.c_str());
  return failed;
}
