// Recording a run (ssx/recording.hpp): samples taken on the stepping thread, written by a thread of
// the recorder's own through a bounded queue.
#include "record/foxglove.hpp"
#include "record/mcap_writer.hpp"
#include "record/pose_codec.hpp"
#include "record/run_channels.hpp"

#include <ssx/command.hpp>
#include <ssx/environment.hpp>
#include <ssx/error.hpp>
#include <ssx/measurements.hpp>
#include <ssx/recording.hpp>
#include <ssx/version.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>

#include <zstd.h>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace ssx {

namespace {

// a JSON message of an optional channel, made on the stepping thread
struct Extra {
  std::uint16_t channel = 0;
  Nanoseconds time = 0;
  std::string json;
};

// one job for the writer: a pose sample (with the optional channels' messages since the last), or
// a saved state
struct Job {
  Nanoseconds time = 0;
  bool state = false;
  std::string attachment;  // a switch of physics engine: the attachment's name (bytes: its text)
  std::vector<std::byte> bytes;
  std::vector<Extra> extras;
  // the sensors, commands and contacts at a pose sample, copied on the stepping thread and
  // written as JSON by the writer (detail::RunSample: the JSON is the costly part)
  std::unique_ptr<detail::RunSample> sample;
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
  std::int64_t states_taken = 0;
  std::vector<std::string> names;
  std::vector<const PhysicNode*> nodes;  // the node heading each name's body
  std::vector<RecordedBody> bodies;
  std::uint16_t poses_channel = 0;
  int tf_channel = -1, timing_channel = -1, sensors_channel = -1, commands_channel = -1,
      contacts_channel = -1;  // -1: not recorded
  std::vector<Extra> extras;                                     // since the last sample
  std::vector<float> tf_positions, tf_orientations;              // the writer thread's
  std::vector<std::byte> packed;                                 // ... (a saved state, compressed)
  struct FreeZstd {
    void operator()(ZSTD_CCtx* c) const noexcept { ZSTD_freeCCtx(c); }
  };
  std::unique_ptr<ZSTD_CCtx, FreeZstd> zstd;  // ... (made at the first state)
  Nanoseconds first_time = -1, last_time = 0;
  std::size_t switches_seen = 0;  // of the environment's switches of physics engine: those written
  bool went_back = false;  // said once: the time went back (a state restored while recording)
  // shared with the writer thread
  mutable std::mutex mutex;
  std::condition_variable changed;
  std::deque<Job> queue;
  std::vector<std::vector<std::byte>> spare;  // buffers the writer is done with
  std::vector<std::byte> spare_state;         // ... and the last saved state's (written over by the next)
  std::vector<std::unique_ptr<detail::RunSample>> spare_samples;  // ... and samples
  bool done = false;
  std::exception_ptr error;
  RecordSummary summary;
  std::thread thread;
  bool finished = false;

  void begin();
  void observe();
  void addJsonChannel(int& channel, const char* topic, const char* schema_name, const char* schema);
  std::string sceneJson() const;
  void takeTiming(const StepTiming& t);
  std::size_t contacts = 0;  // the physics engine's contact points in the step taken last
  void push(Job job);
  void loop();
};

std::vector<RecordedBody> recordedBodies(const Environment& env) {
  std::vector<RecordedBody> out;
  if (env.state() != Environment::State::Running) return out;
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    const Artifact& a = env.artifact(i);
    const PhysicNode* first = nullptr;
    for (std::size_t r = 0; r < a.rootCount() && first == nullptr; ++r)
      if (!a.root(r).isStatic() && a.root(r).bodyIndex() >= 0) first = &a.root(r);
    // (a static-rooted articulation, a door or an arm on a table: its moving parts only, each named
    // for its node, its first not standing for the artifact)
    if (first != nullptr) out.push_back({a.name(), first});
    for (std::size_t k = 0; k < a.nodeCount(); ++k) {
      const PhysicNode& n = a.nodeAt(k);
      if (&n == first || n.isStatic() || n.bodyIndex() < 0) continue;
      if (n.parent() == nullptr || n.joint().isBody()) out.push_back({a.name() + "/" + n.name(), &n});
    }
  }
  return out;
}

const RecordedBody* recordedBodyOf(const std::vector<RecordedBody>& bodies, const PhysicNode& node) {
  for (const PhysicNode* n = &node; n != nullptr; n = n->parent()) {
    if (n->parent() != nullptr && !n->joint().isBody()) continue;  // rigidly part of its parent
    // (the bodies are in artifact order: its artifact's first, then a few more)
    const std::size_t artifact = n->artifact().index();
    auto it = std::lower_bound(bodies.begin(), bodies.end(), artifact, [](const RecordedBody& b, std::size_t i) {
      return b.node->artifact().index() < i;
    });
    for (; it != bodies.end() && it->node->artifact().index() == artifact; ++it)
      if (it->node == n) return &*it;
    return nullptr;
  }
  return nullptr;
}

void Recorder::Impl::begin() {
  begun = true;
  const Nanoseconds tau = env->timestep();
  period_steps = options.rate_hz > 0
                     ? std::max<std::int64_t>(1, std::llround(1.0 / (options.rate_hz * toSeconds(tau))))
                     : 1;
  // the bodies: each artifact's dynamic roots, in artifact order (none known before the start:
  // a recording finished before any step holds the scene and no samples)
  // (and each joined part: a wheel on a hinge is a body of its own)
  bodies = recordedBodies(*env);
  for (const RecordedBody& b : bodies) {
    names.push_back(b.name);
    nodes.push_back(b.node);
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
  summary.channels.push_back("/ssx/poses");
  if (options.foxglove.value_or(names.size() <= RecordOptions::kFoxgloveAutoBodies)) {
    int scene = -1;
    addJsonChannel(tf_channel, "/tf", "foxglove.FrameTransforms", detail::kFrameTransformsSchema);
    addJsonChannel(scene, "/scene", "foxglove.SceneUpdate", detail::kSceneUpdateSchema);
    const std::string update = sceneJson();
    writer->addMessage(static_cast<std::uint16_t>(scene), env->time(),
                       std::as_bytes(std::span(update.data(), update.size())));
  }
  if (options.timing) addJsonChannel(timing_channel, "/ssx/timing", "ssx.StepTiming", detail::kTimingSchema);
  if (options.sensors) addJsonChannel(sensors_channel, "/ssx/sensors", "ssx.Sensors", detail::kSensorsSchema);
  if (options.commands) addJsonChannel(commands_channel, "/ssx/commands", "ssx.Commands", detail::kCommandsSchema);
  if (options.contacts) addJsonChannel(contacts_channel, "/ssx/contacts", "ssx.Contacts", detail::kContactsSchema);
  next_state = env->time();
  thread = std::thread([this] { loop(); });
}

void Recorder::Impl::addJsonChannel(int& channel, const char* topic, const char* schema_name, const char* schema) {
  const std::uint16_t id =
      writer->addSchema(schema_name, "jsonschema", std::as_bytes(std::span(schema, std::char_traits<char>::length(schema))));
  channel = writer->addChannel(id, topic, "json");
  summary.channels.push_back(topic);
}

std::string Recorder::Impl::sceneJson() const { return detail::runSceneUpdate(*env, bodies); }

void Recorder::Impl::takeTiming(const StepTiming& t) {
  const std::string json = detail::timingJson(t, contacts);
  extras.push_back({static_cast<std::uint16_t>(timing_channel), (t.step + 1) * env->timestep(), json});
}

void Recorder::Impl::push(Job job) {
  std::unique_lock lock(mutex);
  if (error) std::rethrow_exception(error);
  if (queue.size() >= options.queue_samples) {
    if (options.drop_when_behind && !job.state && job.attachment.empty() && job.time >= 0) {
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
  if (timing_channel >= 0) {
    // the step before this one: the run loop has told its lateness by now
    const TimingRecorder& timing = env->timing();
    if (timing.size() >= 2 && timing[timing.size() - 2].step + 1 == timing[timing.size() - 1].step)
      takeTiming(timing[timing.size() - 2]);
    contacts = env->physics().contactCount();  // this step's, sent with its timing at the next
  }
  // the switches of physics engine since the last step, each in an attachment of its own
  for (const auto& all = env->physicsSwitches(); switches_seen < all.size(); ++switches_seen) {
    const PhysicsSwitch& x = all[switches_seen];
    Job job;
    job.time = x.time;
    job.attachment = "physics/" + std::to_string(x.time);
    const std::string text = x.from + "\n" + x.to;
    job.bytes.assign(reinterpret_cast<const std::byte*>(text.data()), reinterpret_cast<const std::byte*>(text.data()) + text.size());
    push(std::move(job));
  }
  if (env->stepCount() % period_steps != 0) return;
  Job job;
  job.time = now;
  job.extras.swap(extras);
  {
    std::lock_guard lock(mutex);
    if ((sensors_channel >= 0 || commands_channel >= 0 || contacts_channel >= 0) && !spare_samples.empty()) {
      job.sample = std::move(spare_samples.back());
      spare_samples.pop_back();
    }
    if (!spare.empty()) {
      job.bytes = std::move(spare.back());
      spare.pop_back();
    }
  }
  if (sensors_channel >= 0 || commands_channel >= 0 || contacts_channel >= 0) {
    if (!job.sample) job.sample = std::make_unique<detail::RunSample>();
    if (sensors_channel >= 0) job.sample->takeSensors(*env);
    if (commands_channel >= 0) job.sample->takeCommands(*env);
    if (contacts_channel >= 0) job.sample->takeContacts(*env);
  }
  detail::encodePoses(nodes, job.bytes);
  if (first_time >= 0 && now <= last_time && !went_back) {
    went_back = true;
    env->log(LogLevel::Warning, "recorder: the time went back from " + std::to_string(toSeconds(last_time)) + " s to " +
                                    std::to_string(toSeconds(now)) + " s (a state restored to an earlier time) while "
                                    "recording " + options.file.string() + ": ssx replay and ssx.Recording refuse a "
                                    "recording whose times go back; record each episode into a file of its own");
  }
  if (first_time < 0) first_time = now;
  last_time = now;
  push(std::move(job));
  if (now >= next_state) {
    Job state;
    state.time = now;
    state.state = true;
    {
      std::lock_guard lock(mutex);
      state.bytes.swap(spare_state);
    }
    const auto t0 = std::chrono::steady_clock::now();
    env->saveState(state.bytes);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    {
      std::lock_guard lock(mutex);
      if (states_taken++ == 0)
        summary.state_ms_first = ms;
      else
        summary.state_ms_max = std::max(summary.state_ms_max, ms);
    }
    push(std::move(state));
    next_state = options.state_every_s > 0 ? now + toNanoseconds(options.state_every_s)
                                           : std::numeric_limits<Nanoseconds>::max();
  }
}

void Recorder::Impl::loop() {
  // this thread only (Linux's nice value is per thread); raising one's own never fails for want of
  // rights, and a failure would change nothing but the priority
  if (options.writer_nice != 0)
    (void)setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), options.writer_nice);
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
      // the optional channels' messages first: they are stamped at or before the sample
      for (const Extra& e : job.extras)
        writer->addMessage(e.channel, e.time, std::as_bytes(std::span(e.json.data(), e.json.size())));
      if (!job.attachment.empty()) {
        writer->addAttachment(job.attachment, "text/plain", job.time, job.bytes);
      } else if (job.state) {
        // compressed here, off the stepping thread (21.4 MB at 10,000 quadrotors)
        // (with zstd's checksum: a corrupted frame fails to decompress rather than giving other bytes)
        if (!zstd) {
          zstd.reset(ZSTD_createCCtx());
          if (!zstd) throw Error("cannot compress the saved states of " + options.file.string() + ": out of memory");
          ZSTD_CCtx_setParameter(zstd.get(), ZSTD_c_compressionLevel, 1);
          ZSTD_CCtx_setParameter(zstd.get(), ZSTD_c_checksumFlag, 1);
        }
        packed.resize(ZSTD_compressBound(job.bytes.size()));
        const std::size_t size =
            ZSTD_compress2(zstd.get(), packed.data(), packed.size(), job.bytes.data(), job.bytes.size());
        if (ZSTD_isError(size))
          throw Error("cannot compress a saved state for " + options.file.string() + ": " + ZSTD_getErrorName(size));
        writer->addAttachment("state/" + std::to_string(job.time), "application/x-ssx-state+zstd", job.time,
                              std::span(packed.data(), size));
      } else if (job.time >= 0) {
        if (job.sample) {
          auto json = [&](int channel, const std::string& text) {
            writer->addMessage(static_cast<std::uint16_t>(channel), job.time, std::as_bytes(std::span(text.data(), text.size())));
          };
          if (sensors_channel >= 0) json(sensors_channel, job.sample->sensorsJson(*env));
          if (commands_channel >= 0) json(commands_channel, job.sample->commandsJson(*env));
          if (contacts_channel >= 0) json(contacts_channel, job.sample->contactsJson(*env));
        }
        writer->addMessage(poses_channel, job.time, job.bytes);
        if (tf_channel >= 0) {
          detail::decodePoses(job.bytes, &tf_positions, &tf_orientations);
          const std::string tf = detail::frameTransforms(job.time, names, tf_positions, tf_orientations);
          writer->addMessage(static_cast<std::uint16_t>(tf_channel), job.time, std::as_bytes(std::span(tf.data(), tf.size())));
        }
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
    else if (job.time >= 0 && job.attachment.empty())
      ++summary.samples;
    summary.bytes = writer->bytesWritten();
    if (job.state)
      spare_state = std::move(job.bytes);  // (kept for the next state: 21 MB at 10,000 quadrotors)
    else
      spare.push_back(std::move(job.bytes));
    if (job.sample) spare_samples.push_back(std::move(job.sample));
  }
}

Recorder::Recorder(Environment& env, RecordOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.env = &env;
  m.options = std::move(options);
  if (m.options.file.empty()) throw ConfigError({}, "record: no file given");
  if (!(m.options.rate_hz >= 0 && std::isfinite(m.options.rate_hz)))
    throw ConfigError({}, "record: rate_hz must be 0 (every step) or positive");
  // (a rate so low that its period overflowed would record every step instead)
  if (m.options.rate_hz > 0 && m.options.rate_hz < 1e-6)
    throw ConfigError({}, "record: rate_hz " + std::to_string(m.options.rate_hz) +
                              " is below 1e-6 Hz (one sample in 11.6 days): give 0 (every step) or at least 1e-6");
  if (!(m.options.state_every_s >= 0 && std::isfinite(m.options.state_every_s)))
    throw ConfigError({}, "record: state_every_s must be 0 (the first only) or positive");
  if (m.options.queue_samples < 1) throw ConfigError({}, "record: queue_samples must be at least 1");
  if (m.options.writer_nice < 0 || m.options.writer_nice > 19)
    throw ConfigError({}, "record: writer_nice must be 0 (unchanged) to 19 (a lower priority than the stepping threads)");
  m.writer = std::make_unique<detail::McapWriter>(m.options.file, "ssx", std::string("ssx ") + SSX_VERSION_STRING);
  if (m.options.contacts) env.recordContacts(true);
  m.switches_seen = env.physicsSwitches().size();  // (made before: the saved states say the engine)
  m.listener = env.addStepListener([&m](const Environment&) { m.observe(); });
  m.listening = true;
  prepare();
}

void Recorder::prepare() {
  Impl& m = *impl_;
  if (m.env->state() != Environment::State::Running || m.states_taken > 0) return;
  std::lock_guard lock(m.mutex);
  if (m.spare_state.empty()) m.env->saveState(m.spare_state);
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
  // what the optional channels hold since the last sample, and the last step's timing
  if (m.timing_channel >= 0 && m.env->timing().size() > 0) {
    const TimingRecorder& timing = m.env->timing();
    m.takeTiming(timing[timing.size() - 1]);
  }
  if (!m.extras.empty()) {
    Job job;
    job.time = -1;  // extras only
    job.extras.swap(m.extras);
    m.push(std::move(job));
  }
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
  std::snprintf(text, sizeof text, "%lld samples of %lld bodies (%lld dropped), %lld saved states, %.1f MB",
                static_cast<long long>(samples), static_cast<long long>(bodies), static_cast<long long>(dropped),
                static_cast<long long>(states), static_cast<double>(bytes) / 1e6);
  std::string out = "recording " + file.string() + ": " + text;
  for (std::size_t i = 0; i < channels.size(); ++i) out += (i == 0 ? "; channels " : ", ") + channels[i];
  return out;
}

}  // namespace ssx
