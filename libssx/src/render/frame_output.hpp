#pragma once
// Where a scene camera's frames go: numbered PNG files, an MP4 through an ffmpeg pipe, and a
// snapshot of the last frame written when the run stops.

#include <ssx/render.hpp>

#include <sys/types.h>

#include <cstdio>
#include <functional>
#include <string>
#include <string_view>

namespace ssx::detail {

class FrameOutput {
 public:
  using Warn = std::function<void(std::string_view)>;
  /// Creates the frames directory and starts ffmpeg (with a warning, and no video, when ffmpeg
  /// is not on PATH). Throws Error when the directory cannot be made or ffmpeg cannot start.
  FrameOutput(const CameraSpec& camera, double fps, const Warn& warn);
  ~FrameOutput();
  FrameOutput(const FrameOutput&) = delete;
  FrameOutput& operator=(const FrameOutput&) = delete;

  /// Takes one frame (all frames must have one size).
  void add(const Image& frame);
  /// Ends the video and writes the snapshot; called once when the run stops.
  void finish();
  std::int64_t frames() const noexcept { return frames_; }

 private:
  void startVideo(int width, int height);

  CameraSpec camera_;
  double fps_;
  std::string ffmpeg_;    ///< its full path, found on PATH when the output was made
  int video_fd_ = -1;     ///< the write end of ffmpeg's standard input
  pid_t video_pid_ = -1;
  Image last_;
  std::int64_t frames_ = 0;
  bool finished_ = false;
};

/// The full path of `program` found on PATH, or empty.
std::string findOnPath(std::string_view program);

}  // namespace ssx::detail
