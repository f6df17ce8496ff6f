#pragma once
/// @file
/// Recording a run into one MCAP file (https://mcap.dev), and reading it back.
///
/// A recording holds:
/// - metadata `ssx`: the ssx version, the seed, the timestep, the scene's label; attachment
///   `scene.xml`: the scene model as scene XML (SceneModel::toXml), so that a replay needs no scene file;
/// - metadata `ssx.bodies`: the recorded bodies' names, one per line (an artifact's name, or
///   `artifact/node` for an artifact's second and later dynamic roots);
/// - channel `/ssx/poses` (schema `ssx.Poses`, encoding `ssx.poses.v1`): the pose of every recorded
///   body's root node (what Artifact::pose and Python's positions() give) at the recording rate, compact for whole swarms: a little-endian uint32 body count N, then the fields
///   float32 x, y, z (m, world frame) and int16 qw, qx, qy, qz (the orientation quaternion times
///   32767, sign chosen so that w >= 0), one after another, each as byte planes: byte b of body i's
///   value at (the field's start) + b * N + i (the schema's text says the same);
/// - attachments `state/<nanoseconds>`: saved states (Environment::saveState) at the first sample and
///   then every `state_every_s` of simulated time, from which a run can be continued bitwise;
/// - attachments `physics/<nanoseconds>`: each switch of physics engine (Environment::switchPhysics)
///   at that time, as text: the engine before, a newline, the engine after;
/// - for Foxglove and Lichtblick (RecordOptions::foxglove), in their well-known schemas, JSON-encoded:
///   channel `/tf` (foxglove.FrameTransforms: "world" to each body, at every pose sample) and
///   channel `/scene` (foxglove.SceneUpdate, once: the render trees' shapes, an entity per body
///   locked to its frame, and one for what is fixed in the world);
/// - optional JSON channels: `/ssx/timing` (each step's wall-clock cost by phase and how late it
///   ended) and `/ssx/sensors` (every artifact's IMU, pose and range measurements at each sample),
///   `/ssx/commands` (each commandable robot's command level and values, CommandInterface::currentCommand).
///
/// The stepping thread copies each sample into a buffer and hands it to a writer thread through a
/// bounded queue; compression (zstd) and writing happen there. When the queue is full a real-time
/// run drops the sample (`drop_when_behind`: a step is never held up; the summary counts what was
/// dropped) and a run as fast as possible waits for the writer (nothing is dropped).

#include <ssx/export.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/types.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ssx {

class Environment;
namespace detail {
struct McapFile;
}
class PhysicNode;

/// One body as recordings and the viewer list it.
struct RecordedBody {
  std::string name;                 ///< the artifact's name for its first body, else "artifact/node"
  const PhysicNode* node = nullptr;  ///< the node at the body's head: a dynamic root or a joined node
};

/// Every body of a running environment in recording order: artifact by artifact, its first
/// dynamic root (named as the artifact), then its other dynamic roots and its joined nodes (a wheel
/// on a hinge) in node order, as csv_logger's bodies="all". A static-rooted articulation (a door on
/// its frame, an arm on a table) has its joined nodes only. Empty before start.
SSX_EXPORT std::vector<RecordedBody> recordedBodies(const Environment& env);
/// The recorded body a node moves with: itself if it heads a body, else the nearest ancestor that
/// does; nullptr for a node of a static tree. `bodies` as recordedBodies gives them.
SSX_EXPORT const RecordedBody* recordedBodyOf(const std::vector<RecordedBody>& bodies, const PhysicNode& node);

/// What to record, and how.
struct RecordOptions {
  /// Swarms up to this many bodies get Foxglove's channels unless `foxglove` says otherwise.
  static constexpr std::size_t kFoxgloveAutoBodies = 1000;
  std::filesystem::path file;       ///< the MCAP file written (created, or replaced)
  double rate_hz = 25;              ///< pose samples per simulated second; 0: every step
  double state_every_s = 10;        ///< simulated time between saved states; 0: only the first
  bool drop_when_behind = false;    ///< a full queue drops samples (real-time runs) instead of waiting
  std::size_t queue_samples = 64;   ///< samples that may wait for the writer thread, at most
  /// The writer thread's nice value (Linux: each thread has its own; only the recorder's thread is
  /// changed): 19 lets the stepping threads take a core first when they wake; 0 leaves it as made.
  int writer_nice = 19;
  std::string scene_xml;            ///< the scene as scene XML (SceneModel::toXml), kept in the file
  std::string scene_label;          ///< the scene's file name, for messages
  /// `/tf` and `/scene` for Foxglove and Lichtblick; unset: for at most kFoxgloveAutoBodies bodies
  /// (their JSON is about 15 times the size of the compact poses, and is made on the writer thread)
  std::optional<bool> foxglove;
  bool timing = false;   ///< channel `/ssx/timing`: every step's wall-clock cost
  bool sensors = false;  ///< channel `/ssx/sensors`: IMU, pose and range measurements at each sample
  bool commands = false;  ///< channel `/ssx/commands`: each commandable robot's current command at each sample
  /// channel `/ssx/contacts`: the contacts of the step sampled (pairs, point, normal, impulse);
  /// turns Environment::recordContacts on
  bool contacts = false;
};

/// What a recording wrote (Recorder::finish).
struct SSX_EXPORT RecordSummary {
  std::int64_t samples = 0;  ///< pose samples written
  std::int64_t dropped = 0;  ///< pose samples dropped because the writer was behind
  std::int64_t states = 0;   ///< saved states written
  /// How long the first saved state took on the stepping thread (ms; written into the buffer
  /// Recorder::prepare sized, or sizing it when the recorder could not prepare)
  double state_ms_first = 0;
  double state_ms_max = 0;   ///< the longest of the later ones (ms; the file write is the writer's)
  std::uint64_t bytes = 0;   ///< size of the file
  std::int64_t bodies = 0;   ///< bodies in each sample
  double simulated_s = 0;    ///< time from the first sample to the last
  std::vector<std::string> channels;  ///< the channels' topics, in the file's order
  /// "recording run.mcap: 250 samples of 70 bodies (0 dropped), 2 saved states, 1.2 MB; channels /ssx/poses, /tf, /scene"
  std::string str(const std::filesystem::path& file) const;
};

/// Records an environment's run into an MCAP file, from the next step on, whether the steps come
/// from Environment::step or run (a step listener). Make it before the steps to record and keep it
/// until they are done; finish() (or the destructor) writes the file's end.
class SSX_EXPORT Recorder {
 public:
  /// Checks the options and creates the file (Error if it cannot be: nothing is recorded then).
  Recorder(Environment& env, RecordOptions options);
  /// Finishes, if finish() was not called (errors are then lost: call finish()).
  ~Recorder();
  /// Sizes the buffer saved states are written into by saving one (not recorded), so that the
  /// first recorded state costs the stepping thread what the later ones do (at 10,000 quadrotors
  /// about 20 ms instead of 250-300: the memory of a 21 MB buffer touched the first time). Made on
  /// a running environment, the recorder does it itself; otherwise call it after start(), before a
  /// real-time run. Nothing if the environment is not running or the buffer is sized already.
  void prepare();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Stops recording, waits for the writer, writes the summary section and closes the file.
  /// Throws Error when a write failed (a full disk), naming the file. Once only; later calls
  /// return the same summary.
  RecordSummary finish();
  /// The summary so far.
  RecordSummary summary() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A recording read back (the file's poses in memory): for analysis, replays and re-simulation.
class SSX_EXPORT Recording {
 public:
  /// Reads `file`. Throws Error naming the file and the byte offset when it is not an ssx
  /// recording or is corrupted, when its pose samples' times go back or repeat, or when it is not
  /// a regular file (a FIFO or a device is refused before it is opened); a file cut short (a
  /// killed run) is read up to its last complete chunk (complete() is then false). Reading is
  /// bounded: a chunk is decompressed again when its samples are asked for, one at a time.
  explicit Recording(const std::filesystem::path& file);
  /// The same from bytes in memory; `label` names them in messages.
  Recording(std::vector<std::byte> bytes, const std::filesystem::path& label);
  ~Recording();
  /// Moves the recording read (its memory) into a new one.
  Recording(Recording&&) noexcept;
  /// @copydoc Recording(Recording&&)
  Recording& operator=(Recording&&) noexcept;

  /// The recorded bodies' names.
  const std::vector<std::string>& names() const noexcept;
  /// The sample times, ns, ascending.
  const std::vector<Nanoseconds>& times() const noexcept;
  /// Sample k's positions: names().size() x 3 floats (x, y, z of each body).
  std::vector<float> positions(std::size_t k) const;
  /// Sample k's orientations: names().size() x 4 floats (w, x, y, z of each body, unit).
  std::vector<float> orientations(std::size_t k) const;
  /// The scene model as scene XML.
  const std::string& sceneXml() const noexcept;
  /// The scene's label (its file name when recorded).
  const std::string& sceneLabel() const noexcept;
  /// The ssx version that recorded it.
  const std::string& version() const noexcept;
  /// The seed of the recorded run.
  std::uint64_t seed() const noexcept;
  /// The times of the saved states, ns, ascending.
  std::vector<Nanoseconds> stateTimes() const;
  /// The saved state at or before `time` (its time in `at`), for Environment::restoreState.
  /// Throws Error when there is none that early.
  std::vector<std::byte> stateAtOrBefore(Nanoseconds time, Nanoseconds* at = nullptr) const;
  /// The switches of physics engine made while recording, in order (a re-simulation makes them
  /// again at their times).
  std::vector<PhysicsSwitch> physicsSwitches() const;
  /// Whether the file ends as a finished recording does (summary and footer).
  bool complete() const noexcept;
  /// The messages of channel `topic` (log time in ns, the message's bytes), in the file's order
  /// (ascending time within a channel). Throws Error naming the channels there are when there is
  /// no such channel.
  std::vector<std::pair<Nanoseconds, std::string>> messages(const std::string& topic) const;
  /// The last message of channel `topic` logged at or before `time` (log time in ns, its bytes):
  /// one message read, for a replay that shows what was recorded at a time. Nothing when the
  /// channel has none that early, or when there is no such channel.
  std::optional<std::pair<Nanoseconds, std::string>> messageAtOrBefore(const std::string& topic, Nanoseconds time) const;
  /// The message encoding of channel `topic` ("json", "ssx.poses.v1"), or "" when there is none.
  std::string encoding(const std::string& topic) const;
  /// Every channel's topic and message count, in id order.
  std::vector<std::pair<std::string, std::uint64_t>> channels() const;
  /// Bytes in the file.
  std::uint64_t size() const noexcept;

 private:
  explicit Recording(detail::McapFile file);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Writes a complete copy of a recording that was cut short (a killed run: no summary, no
/// footer) to `out`: everything up to its last complete chunk, with the summary a finished file has.
/// Works on complete files too (a plain copy of their contents). Throws Error naming the file.
SSX_EXPORT void completeRecording(const std::filesystem::path& damaged, const std::filesystem::path& out);

}  // namespace ssx
