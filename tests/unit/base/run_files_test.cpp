// A run's files (ssx/run_files.hpp): outputs are never inputs nor each other, by identity, and are
// regular or new files.
#include <ssx/run_files.hpp>

#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

using namespace ssx;
namespace fs = std::filesystem;

namespace {

// a directory of this test's own: ctest runs the cases in parallel processes, and a fixed name had
// one case remove the directory another was using
struct Dir {
  fs::path path;
  Dir() {
    std::string pattern = (fs::temp_directory_path() / "ssx_run_files_XXXXXX").string();
    REQUIRE(mkdtemp(pattern.data()) != nullptr);
    path = pattern;
    fs::create_directories(path / "sub");
  }
  ~Dir() { fs::remove_all(path); }
  fs::path file(const std::string& name, const std::string& text = "x") const {
    std::ofstream(path / name) << text;
    return path / name;
  }
};

}  // namespace

TEST_CASE("an output that is an input of the run, by any spelling or link, is refused", "[run_files]") {
  Dir d;
  const fs::path scene = d.file("scene.xml");
  RunFiles files;
  files.addInput(scene);
  CHECK_THAT(files.claimOutput(scene, "--save-state"), Catch::Contains("which this run reads"));
  CHECK_THAT(files.claimOutput(d.path / "sub" / ".." / "scene.xml", "--save-state"), Catch::Contains("which this run reads"));
  fs::create_hard_link(scene, d.path / "hard.xml");
  CHECK_THAT(files.claimOutput(d.path / "hard.xml", "--stats-csv"), Catch::Contains("which this run reads"));
  fs::create_symlink(scene, d.path / "link.xml");
  CHECK_THAT(files.claimOutput(d.path / "link.xml", "--stats-csv"), Catch::Contains("symbolic link"));
  CHECK(files.outputs().empty());
  CHECK(fs::file_size(scene) == 1);  // (nothing was opened)
}

TEST_CASE("two outputs onto one file are refused, however the second is spelled", "[run_files]") {
  Dir d;
  RunFiles files;
  CHECK(files.claimOutput(d.path / "dup.csv", "parameter 'file'").empty());
  CHECK_THAT(files.claimOutput(d.path / "sub" / ".." / "dup.csv", "parameter 'file'"),
             Catch::Contains("which this run writes already"));
  const fs::path existing = d.file("old.csv");
  CHECK(files.claimOutput(existing, "--stats-csv").empty());  // an existing regular file is replaced
  CHECK_THAT(files.claimOutput(existing, "--out"), Catch::Contains("writes already"));
}

TEST_CASE("outputs must be regular or new files in an existing directory, streams may be special when allowed",
          "[run_files]") {
  Dir d;
  RunFiles files;
  CHECK_THAT(files.claimOutput(d.path / "none" / "x.csv", "--stats-csv"), Catch::Contains("does not exist"));
  CHECK(files.claimOutput(d.path / "none" / "x.png", "camera 'c': snapshot", false, true).empty());  // its writer makes it
  CHECK_THAT(files.claimOutput(d.path / "sub", "--stats-csv"), Catch::Contains("is a directory"));
  REQUIRE(::mkfifo((d.path / "fifo").c_str(), 0600) == 0);
  CHECK_THAT(files.claimOutput(d.path / "fifo", "--save-state", true), Catch::Contains("not a regular file"));
  CHECK_THAT(files.claimOutput(d.path / "fifo", "parameter 'file'"), Catch::Contains("--allow-special-outputs"));
  files.allowSpecialOutputs(true);
  CHECK(files.claimOutput(d.path / "fifo", "parameter 'file'").empty());  // a stream into a pipe
  CHECK_THAT(files.claimOutput("/dev/null", "--save-state", true), Catch::Contains("not a regular file"));
  CHECK(fs::is_fifo(d.path / "fifo"));
}

TEST_CASE("a frames directory may not hold an input of the run", "[run_files]") {
  Dir d;
  RunFiles files;
  files.addInput(d.file("scene.xml"));
  CHECK_THAT(files.claimOutputDirectory(d.path, "camera 'c': frames"), Catch::Contains("holds"));
  CHECK(files.claimOutputDirectory(d.path / "frames", "camera 'c': frames").empty());
}

TEST_CASE("input files: regular files up to the limit are read whole, anything else is refused saying why",
          "[run_files]") {
  const Dir dir;
  const fs::path small = dir.file("small.xml", std::string(1000, 'a'));
  CHECK(readInputFile(small) == std::string(1000, 'a'));
  CHECK(readInputFile(small, 1000).size() == 1000);  // the limit itself is allowed
  CHECK_THROWS_WITH(readInputFile(small, 999), Catch::Contains("small.xml: error: cannot read it: larger than the "
                                                               "limit on input files") &&
                                                   Catch::Contains("--max-input-mb"));
  // a device with no end, a FIFO, a directory, a missing file: errors, never a read without bound
  CHECK_THROWS_WITH(readInputFile("/dev/zero"), Catch::Contains("/dev/zero: error: cannot read it: not a regular file"));
  const fs::path fifo = dir.path / "pipe";
  REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
  CHECK_THROWS_WITH(readInputFile(fifo), Catch::Contains("not a regular file"));  // (opening it would block)
  CHECK_THROWS_WITH(readInputFile(dir.path / "sub"), Catch::Contains("a directory, not a file"));
  CHECK_THROWS_WITH(readInputFile(dir.path / "none.xml"), Catch::Contains("none.xml: error: cannot read it: No such file"));
  // a link to a file reads the file
  fs::create_symlink(small, dir.path / "link.xml");
  CHECK(readInputFile(dir.path / "link.xml").size() == 1000);
}
