#pragma once
// Draws the scene cameras' frames on a thread of its own, so that a run in real time does not wait
// for the renderer or the PNG/video encoders. The render phase hands over a copy of the posed
// render nodes and the camera views (cheap); the worker draws them with its own render engine
// (its OpenGL context lives on the worker thread) and passes the images to the outputs.
// At most `depth` frames wait; a step that finds the queue full waits for room.

#include "render/frame_output.hpp"

#include <ssx/render.hpp>

#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace ssx::detail {

class FrameWorker {
 public:
  struct Posed {
    const RenderNodeSpec* spec;
    Pose world;
  };
  FrameWorker(const RenderSettings& settings, std::vector<std::unique_ptr<FrameOutput>> outputs,
              std::size_t depth = 16);
  ~FrameWorker();
  FrameWorker(const FrameWorker&) = delete;
  FrameWorker& operator=(const FrameWorker&) = delete;

  /// Queues one frame of simulated time `time`: views[i] is drawn for outputs[i] (stamped with
  /// the time when the settings ask for it). Rethrows the worker's first error.
  void submit(const std::vector<RenderNode>& nodes, std::vector<CameraView> views, Nanoseconds time = 0);
  /// Draws what is queued, ends the thread, finishes the outputs; rethrows the first error.
  void finish();

 private:
  struct Job {
    std::vector<RenderNode> nodes;
    std::vector<CameraView> views;
    Nanoseconds time = 0;
  };
  void loop();

  RenderSettings settings_;
  std::vector<std::unique_ptr<FrameOutput>> outputs_;
  std::size_t depth_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> queue_;
  std::vector<Job> spare_;  // drawn jobs, their vectors reused
  bool done_ = false;
  bool finished_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace ssx::detail
