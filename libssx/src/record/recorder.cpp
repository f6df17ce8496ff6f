// Recording a run (ssx/recording.hpp): samples taken on the stepping thread, written by a thread of
// the recorder's own through a bounded queue.
#include "record/mcap_writer.hpp"
#include "record/pose_codec.hpp"

#include <ssx/environment.hpp>
#include <ssx/error.hpp>
#include <ssx/recording.hpp>
#include <ssx/version.hpp>

#include <condition_variable>
#include <cmath>
#include <cstdio>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

namespace ssx {

namespace {

// one job for the writer: a pose sample, or a saved state
struct Job {
  Nanoseconds time = 0;
  bool state = false;
  std::vector<std::byte> bytes;
};

}  // namespace

struct Recorder::Impl {
  Environment* env = nullptr;
  RecordOptions options;
  std::unique_ptr<detail::McapWriter> writer;
  std::size_t listener = 0;
  bool listening = false;
  // what the stepping thread keeps
  bool begun = false;
  std::int64_t period_steps = 1;
  Nanoseconds next_state = 0;
  std::vector<std::string> names;
  std::vector<const PhysicNode*> nodes;  // the root node of each name
  std::uint16_t poses_channel = 0;
  Nanoseconds first_time = -1, last_time = 0;
  // shared with the writer thread
  mutable std::mutex mutex;
  std::condition_variable changed;
  std::deque<Job> queue;
  std::vector<std::vector<std::byte>> spare;  // buffers the writer is done with
  bool done = false;
  std::exception_ptr error;
  RecordSummary summary;
  std::thread thread;
  bool finished = false;

  void begin();
  void observe();
  void push(Job job);
  void loop();
};

void Recorder::Impl::begin() {
  begun = true;
  const Nanoseconds tau = env->timestep();
  period_steps = options.rate_hz > 0
                     ? std::max<std::int64_t>(1, std::llround(1.0 / (options.rate_hz * toSeconds(tau))))
                     : 1;
  // the bodies: each artifact's dynamic roots, in artifact order (none known before the start:
  // a recording finished before any step holds the scene and no samples)
  const bool running = env->state() == Environment::State::Running;
  for (std::size_t i = 0; running && i < env->artifactCount(); ++i) {
    const Artifact& a = std::as_const(*env).artifact(i);
    bool first = true;
    for (std::size_t r = 0; r < a.rootCount(); ++r) {
      const PhysicNode& root = a.root(r);
      if (root.isStatic() || root.bodyIndex() < 0) continue;
      names.push_back(first ? a.name() : a.name() + "/" + root.name());
      nodes.push_back(&root);
      first = false;
    }
  }
  summary.bodies = static_cast<std::int64_t>(names.size());
  std::string joined;
  for (const auto& n : names) joined += n + "\n";
  writer->addMetadata("ssx", {{"version", SSX_VERSION_STRING},
                              {"seed", std::to_string(env->settings().seed)},
                              {"timestep_ns", std::to_string(tau)},
                              {"scene", options.scene_label},
                              {"bodies", std::to_string(names.size())}});
  writer->addMetadata("ssx.bodies", {{"names", joined}});
  writer->addAttachment("scene.xml", "application/xml", env->time(),
                        std::as_bytes(std::span(options.scene_xml.data(), options.scene_xml.size())));
  const std::string layout = detail::kPoseLayout;
  const std::uint16_t schema =
      writer->addSchema("ssx.Poses", "", std::as_bytes(std::span(layout.data(), layout.size())));
  poses_channel = writer->addChannel(schema, "/ssx/poses", "ssx.poses.v1", {{"bodies", std::to_string(names.size())}});
  next_state = env->time();
  thread = std::thread([this] { loop(); });
}

void Recorder::Impl::push(Job job) {
  std::unique_lock lock(mutex);
  if (error) std::rethrow_exception(error);
  if (queue.size() >= options.queue_samples) {
    if (options.drop_when_behind && !job.state) {
      ++summary.dropped;
      spare.push_back(std::move(job.bytes));
      return;
    }
    changed.wait(lock, [&] { return queue.size() < options.queue_samples || error != nullptr; });
    if (error) std::rethrow_exception(error);
  }
  queue.push_back(std::move(job));
  changed.notify_all();
}

void Recorder::Impl::observe() {
  if (!begun) begin();
  const Nanoseconds now = env->time();
  if (env->stepCount() % period_steps != 0) return;
  Job job;
  job.time = now;
  {
    std::lock_guard lock(mutex);
    if (!spare.empty()) {
      job.bytes = std::move(spare.back());
      spare.pop_back();
    }
  }
  detail::encodePoses(nodes, job.bytes);
  if (first_time < 0) first_time = now;
  last_time = now;
  push(std::move(job));
  if (now >= next_state) {
    Job state;
    state.time = now;
    state.state = true;
    state.bytes = env->saveState();
    push(std::move(state));
    next_state = options.state_every_s > 0 ? now + toNanoseconds(options.state_every_s)
                                           : std::numeric_limits<Nanoseconds>::max();
  }
}

void Recorder::Impl::loop() {
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex);
      changed.wait(lock, [&] { return !queue.empty() || done; });
      if (queue.empty()) return;
      job = std::move(queue.front());
      queue.pop_front();
      changed.notify_all();
    }
    try {
      if (job.state) {
        writer->addAttachment("state/" + std::to_string(job.time), "application/x-ssx-state", job.time, job.bytes);
      } else {
        writer->addMessage(poses_channel, job.time, job.bytes);
      }
    } catch (...) {
      std::lock_guard lock(mutex);
      if (!error) error = std::current_exception();
      queue.clear();
      changed.notify_all();
      return;
    }
    std::lock_guard lock(mutex);
    if (job.state)
      ++summary.states;
    else
      ++summary.samples;
    summary.bytes = writer->bytesWritten();
    spare.push_back(std::move(job.bytes));
  }
}

Recorder::Recorder(Environment& env, RecordOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.env = &env;
  m.options = std::move(options);
  if (m.options.file.empty()) throw ConfigError({}, "record: no file given");
  if (!(m.options.rate_hz >= 0 && std::isfinite(m.options.rate_hz)))
    throw ConfigError({}, "record: rate_hz must be 0 (every step) or positive");
  if (!(m.options.state_every_s >= 0 && std::isfinite(m.options.state_every_s)))
    throw ConfigError({}, "record: state_every_s must be 0 (the first only) or positive");
  if (m.options.queue_samples < 1) throw ConfigError({}, "record: queue_samples must be at least 1");
  m.writer = std::make_unique<detail::McapWriter>(m.options.file, "ssx", std::string("ssx ") + SSX_VERSION_STRING);
  m.listener = env.addStepListener([&m](const Environment&) { m.observe(); });
  m.listening = true;
}

Recorder::~Recorder() {
  try {
    finish();
  } catch (...) {
  }
}

RecordSummary Recorder::finish() {
  Impl& m = *impl_;
  if (m.finished) return summary();
  m.finished = true;
  if (m.listening) m.env->removeStepListener(m.listener);
  m.listening = false;
  if (!m.begun) m.begin();  // no step was taken: the scene and no samples
  {
    std::lock_guard lock(m.mutex);
    m.done = true;
    m.changed.notify_all();
  }
  if (m.thread.joinable()) m.thread.join();
  if (m.error) std::rethrow_exception(m.error);
  m.writer->close();
  std::lock_guard lock(m.mutex);
  m.summary.bytes = m.writer->bytesWritten();
  m.summary.simulated_s = m.first_time >= 0 ? toSeconds(m.last_time - m.first_time) : 0;
  return m.summary;
}

RecordSummary Recorder::summary() const {
  std::lock_guard lock(impl_->mutex);
  RecordSummary s = impl_->summary;
  s.simulated_s = impl_->first_time >= 0 ? toSeconds(impl_->last_time - impl_->first_time) : 0;
  return s;
}

std::string RecordSummary::str(const std::filesystem::path& file) const {
  char text[256];
  std::snprintf(text, sizeof text, "recording %s: %lld samples of %lld bodies (%lld dropped), %lld saved states, %.1f MB",
                file.string().c_str(), static_cast<long long>(samples), static_cast<long long>(bodies),
                static_cast<long long>(dropped), static_cast<long long>(states), static_cast<double>(bytes) / 1e6);
  return text;
}

}  // namespace ssx
