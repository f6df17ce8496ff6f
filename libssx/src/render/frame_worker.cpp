#include "render/frame_worker.hpp"
#include "render/time_stamp.hpp"

#include <pthread.h>
#include <sys/resource.h>
#include <csignal>
#include <unistd.h>

namespace ssx::detail {

FrameWorker::FrameWorker(const RenderSettings& settings, std::vector<std::unique_ptr<FrameOutput>> outputs,
                         std::size_t depth)
    : settings_(settings), outputs_(std::move(outputs)), depth_(depth) {
  thread_ = std::thread([this] { loop(); });
}

FrameWorker::~FrameWorker() {
  try {
    finish();
  } catch (...) {
  }
}

void FrameWorker::submit(const std::vector<RenderNode>& nodes, std::vector<CameraView> views, Nanoseconds time) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return queue_.size() < depth_ || error_; });
  if (error_) std::rethrow_exception(error_);
  Job job;
  if (!spare_.empty()) {
    job = std::move(spare_.back());
    spare_.pop_back();
  }
  job.nodes.assign(nodes.begin(), nodes.end());
  job.views = std::move(views);
  job.time = time;
  queue_.push_back(std::move(job));
  changed_.notify_all();
}

void FrameWorker::loop() {
  // below the simulation's threads: on a busy machine the steps come first and frames wait
  setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
  // a video pipe whose ffmpeg died must give an error (EPIPE), not kill the embedding program:
  // SIGPIPE is blocked on this thread only, the one that writes to the pipes
  sigset_t pipe_signal;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_signal, nullptr);
  std::unique_ptr<RenderEngine> engine;
  Image image;
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return !queue_.empty() || done_; });
      if (queue_.empty()) return;  // done and drained
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    try {
      if (!engine) engine = createRenderEngine(settings_);  // its context is made on this thread
      for (std::size_t i = 0; i < job.views.size() && i < outputs_.size(); ++i) {
        engine->renderView(job.views[i], job.nodes, settings_.background, image);
        if (settings_.time_stamp) stampTime(image, job.time);
        outputs_[i]->add(image);
      }
    } catch (...) {
      std::lock_guard lock(mutex_);
      if (!error_) error_ = std::current_exception();
      queue_.clear();
      changed_.notify_all();
      return;
    }
    std::lock_guard lock(mutex_);
    spare_.push_back(std::move(job));
    changed_.notify_all();
  }
}

void FrameWorker::finish() {
  if (finished_) return;
  finished_ = true;
  {
    std::lock_guard lock(mutex_);
    done_ = true;
    changed_.notify_all();
  }
  if (thread_.joinable()) thread_.join();
  std::exception_ptr error = error_;
  for (auto& o : outputs_) {
    try {
      o->finish();
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace ssx::detail
