// Frame outputs: a video goes to ffmpeg as one argument, and a failing ffmpeg is reported.
// Headless (OSMesa); every test name contains "render".
#include <ssx/ssx.hpp>

#include "render_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

using namespace ssx;
using namespace ssx::test;
namespace fs = std::filesystem;

namespace {

// a stand-in ffmpeg (a shell script) first on PATH for as long as it lives; PATH is put back after,
// so later tests in this process find the real one
class FakeFfmpeg {
 public:
  explicit FakeFfmpeg(const std::string& script) {
    const fs::path bin = fs::current_path() / "bin";
    fs::create_directories(bin);
    std::ofstream(bin / "ffmpeg") << "#!/bin/sh\n" << script;
    fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
    const char* path = std::getenv("PATH");
    had_path_ = path != nullptr;
    if (had_path_) old_path_ = path;
    REQUIRE(setenv("PATH", (bin.string() + ":" + (had_path_ ? old_path_ : "/usr/bin:/bin")).c_str(), 1) == 0);
  }
  ~FakeFfmpeg() {
    if (had_path_)
      setenv("PATH", old_path_.c_str(), 1);
    else
      unsetenv("PATH");
  }
  FakeFfmpeg(const FakeFfmpeg&) = delete;
  FakeFfmpeg& operator=(const FakeFfmpeg&) = delete;

 private:
  bool had_path_ = false;
  std::string old_path_;
};

}  // namespace

TEST_CASE("render: a video path is only a file name: ffmpeg gets it as one argument, never through a shell",
          "[render][video]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  // a stand-in ffmpeg: copies its input to the file named by its last argument
  const FakeFfmpeg ffmpeg("for a in \"$@\"; do last=\"$a\"; done\ncat > \"${last#file:}\"\n");
  // a shell would run "touch pwned" (the quote ends the quoted name); an argument vector does not
  const fs::path video = fs::current_path() / "clip'; touch pwned; echo '.mp4";
  Scene s = loadRenderScene(R"(<render engine="osmesa" rate_hz="10" width="64" height="48">
      <camera name="side" xyz="0 -6 2" look_at="0 0 1" video=")" + video.string() + R"("/>
    </render><ground/>
    <type name="ball" file="yellow_ball.xml"/><artifact name="ball" type="ball" xyz="0 0 2"/>)");
  s.environment->step(250);  // frames at steps 0, 50, ..., 200
  s.environment->stop();
  REQUIRE(fs::exists(video));
  CHECK(fs::file_size(video) == 5u * 64 * 48 * 3);
  CHECK_FALSE(fs::exists("pwned"));
  CHECK_FALSE(fs::exists(video.string() + ".ffmpeg.log"));  // removed after ffmpeg succeeded
}

TEST_CASE("render: an ffmpeg that fails makes stopping fail with the video's name", "[render][video]") {
  REQUIRE(haveOsmesa());
  const FakeFfmpeg ffmpeg("echo 'no encoder here' >&2\nexit 1\n");
  Scene s = loadRenderScene(R"(<render engine="osmesa" rate_hz="10" width="64" height="48">
      <camera name="side" xyz="0 -6 2" look_at="0 0 1" video="out.mp4"/>
    </render><ground/>
    <type name="ball" file="yellow_ball.xml"/><artifact name="ball" type="ball" xyz="0 0 2"/>)");
  // the dead pipe is found by a frame write (EPIPE, no SIGPIPE) or by ffmpeg's exit status
  bool reported = false;
  try {
    s.environment->step(250);
  } catch (const StepError& e) {
    CHECK_THAT(e.what(), Catch::Contains("out.mp4"));
    reported = true;
  }
  try {
    s.environment->stop();
  } catch (const Error& e) {
    CHECK_THAT(e.what(), Catch::Contains("ffmpeg") && Catch::Contains("out.mp4"));
    reported = true;
  }
  CHECK(reported);
  CHECK_THAT(fileText("out.mp4.ffmpeg.log"), Catch::Contains("no encoder here"));
}
