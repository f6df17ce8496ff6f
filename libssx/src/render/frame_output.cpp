#include "render/frame_output.hpp"

#include <ssx/error.hpp>
#include <ssx/run_files.hpp>

#include <fcntl.h>
#include <png.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;  // the environment ffmpeg inherits

namespace ssx {

void writePng(const std::filesystem::path& file, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3)
    throw Error("cannot write " + file.string() + ": the image is empty or its size does not match its pixels");
  std::FILE* f = openOutputFile(file);  // (locked: a second run writing the same picture is refused)
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, info != nullptr ? &info : nullptr);
    std::fclose(f);
    throw Error("cannot write " + file.string() + ": libpng failed (disk full?)");
  }
  png_init_io(png, f);
  // speed over size: frames are written while the simulation runs
  png_set_compression_level(png, 1);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(image.rgb.data() + static_cast<std::size_t>(y) * image.width * 3));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(f) != 0) throw Error("cannot write " + file.string() + ": " + std::strerror(errno));
}

namespace detail {

std::string findOnPath(std::string_view program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::filesystem::path candidate = std::filesystem::path(dir) / program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return {};
}

FrameOutput::FrameOutput(const CameraSpec& camera, double fps, const Warn& warn) : camera_(camera), fps_(fps) {
  if (!camera_.frames_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(camera_.frames_dir, ec);
    if (ec) throw Error("camera '" + camera_.name + "': cannot create " + camera_.frames_dir.string() + ": " + ec.message());
  }
  if (!camera_.video.empty() && findOnPath("ffmpeg").empty()) {
    warn("camera '" + camera_.name + "': ffmpeg is not installed (not on PATH), so no video is written to " +
         camera_.video.string() + "; install it (apt-get install ffmpeg) or use frames=\"DIR\" for PNG frames");
    camera_.video.clear();
  }
  if (!camera_.video.empty()) ffmpeg_ = findOnPath("ffmpeg");
}

void FrameOutput::startVideo(int width, int height) {
  // ffmpeg gets an argument vector, not a shell line: the video's path is one argument whatever
  // characters it holds. Its own messages go to a log beside the video, so that a failure can
  // be read; it runs at a lower priority (nice) than the simulation.
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.9g", fps_);
  std::vector<std::string> args = {"nice", "-n", "10", ffmpeg_, "-nostdin", "-y", "-loglevel", "error",
                                   "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", size, "-r", rate, "-i", "pipe:0",
                                   "-c:v", "libx264", "-preset", "ultrafast", "-crf", "23", "-pix_fmt", "yuv420p"};
  // yuv420p needs even sizes
  if (width % 2 != 0 || height % 2 != 0) args.insert(args.end(), {"-vf", "crop=trunc(iw/2)*2:trunc(ih/2)*2"});
  args.push_back("file:" + camera_.video.string());  // "file:" so that a name like "-x.mp4" is no option
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw Error("camera '" + camera_.name + "': cannot start ffmpeg: " + std::strerror(errno));
  const std::string log = camera_.video.string() + ".ffmpeg.log";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  const int failed = ::posix_spawnp(&pid, "nice", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (failed != 0) {
    ::close(fds[1]);
    throw Error("camera '" + camera_.name + "': cannot start ffmpeg: " + std::strerror(failed));
  }
  video_fd_ = fds[1];
  video_pid_ = pid;
}

FrameOutput::~FrameOutput() {
  try {
    finish();
  } catch (...) {
  }
}

void FrameOutput::add(const Image& frame) {
  if (!camera_.frames_dir.empty()) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06lld.png", static_cast<long long>(frames_));
    writePng(camera_.frames_dir / name, frame);
  }
  if (!camera_.video.empty()) {
    if (video_pid_ < 0) startVideo(frame.width, frame.height);  // when the first frame's size is known
    const auto* data = reinterpret_cast<const char*>(frame.rgb.data());
    std::size_t left = frame.rgb.size();
    while (left > 0) {
      const ssize_t n = ::write(video_fd_, data, left);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0)
        throw Error("camera '" + camera_.name + "': ffmpeg stopped taking frames for " + camera_.video.string() +
                    " (see " + camera_.video.string() + ".ffmpeg.log)");
      data += n;
      left -= static_cast<std::size_t>(n);
    }
  }
  if (!camera_.snapshot.empty()) last_ = frame;
  ++frames_;
}

void FrameOutput::finish() {
  if (finished_) return;
  finished_ = true;
  if (video_pid_ >= 0) {
    ::close(video_fd_);  // ffmpeg sees the end of its input and finishes the file
    video_fd_ = -1;
    int status = 0;
    pid_t waited;
    do waited = ::waitpid(video_pid_, &status, 0);
    while (waited < 0 && errno == EINTR);
    video_pid_ = -1;
    if (waited < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
      throw Error("camera '" + camera_.name + "': ffmpeg failed writing " + camera_.video.string() + " (see " +
                  camera_.video.string() + ".ffmpeg.log)");
    std::filesystem::remove(camera_.video.string() + ".ffmpeg.log");
  }
  if (!camera_.snapshot.empty() && frames_ > 0) {
    if (camera_.snapshot.has_parent_path()) std::filesystem::create_directories(camera_.snapshot.parent_path());
    writePng(camera_.snapshot, last_);
  }
}

}  // namespace detail
}  // namespace ssx
