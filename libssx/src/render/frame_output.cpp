#include "render/frame_output.hpp"

#include <ssx/error.hpp>

#include <png.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace ssx {

void writePng(const std::filesystem::path& file, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3)
    throw Error("cannot write " + file.string() + ": the image is empty or its size does not match its pixels");
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (f == nullptr) throw Error("cannot write " + file.string() + ": " + std::strerror(errno));
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
    if (video_ == nullptr) {
      // started with the first frame, when its size is known; ffmpeg's own output goes to a log
      // beside the video so that a failure can be read
      std::ostringstream cmd;
      const std::string log = camera_.video.string() + ".ffmpeg.log";
      cmd << "nice -n 10 ffmpeg -y -loglevel error -f rawvideo -pix_fmt rgb24 -s " << frame.width << 'x' << frame.height
          << " -r " << fps_ << " -i - -c:v libx264 -preset ultrafast -crf 23 -pix_fmt yuv420p";
      // yuv420p needs even sizes
      if (frame.width % 2 != 0 || frame.height % 2 != 0) cmd << " -vf crop=trunc(iw/2)*2:trunc(ih/2)*2";
      cmd << " '" << camera_.video.string() << "' 2>'" << log << "'";
      video_ = ::popen(cmd.str().c_str(), "w");
      if (video_ == nullptr) throw Error("camera '" + camera_.name + "': cannot start ffmpeg: " + std::strerror(errno));
    }
    if (std::fwrite(frame.rgb.data(), 1, frame.rgb.size(), video_) != frame.rgb.size())
      throw Error("camera '" + camera_.name + "': ffmpeg stopped taking frames (see " + camera_.video.string() +
                  ".ffmpeg.log)");
  }
  if (!camera_.snapshot.empty()) last_ = frame;
  ++frames_;
}

void FrameOutput::finish() {
  if (finished_) return;
  finished_ = true;
  if (video_ != nullptr) {
    const int status = ::pclose(video_);
    video_ = nullptr;
    if (status != 0)
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
