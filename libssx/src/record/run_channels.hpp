#pragma once
// The JSON channels a run offers beside its poses, the same in a recording (Recorder) and live
// (the foxglove extension), so that one Foxglove layout serves both:
// - /scene (foxglove.SceneUpdate): every artifact's shapes, in the frame of the body it moves with;
// - /ssx/timing (ssx.StepTiming): one step's wall-clock cost;
// - /ssx/sensors (ssx.Sensors): each artifact's latest measurements;
// - /ssx/commands (ssx.Commands): each commandable robot's current command;
// - /ssx/contacts (ssx.Contacts): the contacts of a step (Environment::recordContacts must be on).
// Each function reads the environment: call it on the stepping thread (or while it stands).

#include <ssx/command.hpp>
#include <ssx/measurements.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/recording.hpp>
#include <ssx/timing.hpp>
#include <ssx/types.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace ssx {
class Environment;
}

namespace ssx::detail {

/// JSON Schemas of the messages below (only the fields written).
extern const char* const kTimingSchema;
extern const char* const kSensorsSchema;
extern const char* const kCommandsSchema;
extern const char* const kContactsSchema;

/// foxglove.SceneUpdate of a running environment: each render tree in the frame of the recorded
/// body (`bodies`, as recordedBodies gives them) it moves with, or of the world.
std::string runSceneUpdate(const Environment& env, const std::vector<RecordedBody>& bodies);
/// What /ssx/sensors and /ssx/commands hold, copied on the stepping thread (a few hundred
/// nanoseconds a robot, with no allocation once the vectors have grown) and written as JSON on any
/// thread later: the JSON is the costly part (about 16 us a robot with a range sensor that sees its
/// neighbours). Writing reads the environment's artifact names only (fixed while it runs).
class RunSample {
 public:
  /// Each artifact's latest measurements of the kinds measurementJson writes.
  void takeSensors(const Environment& env);
  /// The same of artifact `artifact` alone (a robot's own channel).
  void takeSensorsOf(const Environment& env, std::size_t artifact);
  /// Each commandable robot's current command.
  void takeCommands(const Environment& env);
  /// /ssx/sensors from the sensors taken: {"<artifact>": {"0": {measurement}, ...}, ...}.
  std::string sensorsJson(const Environment& env) const;
  /// What one artifact's entry in sensorsJson holds, of the sensors taken: {"0": {measurement}, ...}.
  std::string artifactSensorsJson(const Environment& env) const;
  /// The first IMU measurement taken, or null.
  const ImuMeasurement* firstImu() const;
  /// /ssx/commands from the commands taken: {"<artifact>": {"level": "attitude", "values": [...]}, ...}.
  std::string commandsJson(const Environment& env) const;
  /// The contacts of the last step (the environment records them).
  void takeContacts(const Environment& env);
  /// /ssx/contacts from the contacts taken: {"contacts": [{"a": artifact, "b": artifact or static
  /// artifact, "position": [x, y, z], "normal": [x, y, z], "impulse": N s}, ...]}.
  std::string contactsJson(const Environment& env) const;

 private:
  enum class Kind : std::uint8_t { Imu, Pose, Range };
  // a sensor whose measurements are written, found once: its output is a member of the sensor,
  // at the same address while the environment runs, and its kind never changes
  struct Source {
    std::size_t artifact = 0, index = 0;
    Kind kind = Kind::Imu;
    std::size_t slot = 0;  // where its copy is in its kind's vector below
    const Measurement* latest = nullptr;
  };
  std::vector<Source> sources_;
  static constexpr std::size_t kAllArtifacts = ~std::size_t{0};
  const Environment* sources_of_ = nullptr;       // the environment sources_ were found in ...
  std::size_t sources_artifact_ = kAllArtifacts;  // ... and of which artifact (kAllArtifacts: every one)
  void take(const Environment& env, std::size_t artifact);
  void appendArtifact(std::string& out, const Environment& env, std::size_t& k) const;
  // what each source measured last, in its kind's vector (dense: a copy touches only its own)
  std::vector<ImuMeasurement> imus_;
  std::vector<PoseMeasurement> poses_;
  std::vector<RangeMeasurement> ranges_;
  const Measurement& copyOf(const Source& source) const;
  mutable std::size_t sensors_json_size_ = 0;  // room for the next /ssx/sensors (the last one's, and more)
  std::vector<std::pair<std::size_t, const CommandInterface*>> commandables_;  // found once, as sources_
  const Environment* commandables_of_ = nullptr;
  std::vector<std::pair<std::size_t, Command>> commands_;  // per commandable: its current command
  std::vector<EngineContact> contacts_;
};

/// /ssx/timing: one step's cost, ms, and the physics engine's contact points in it.
std::string timingJson(const StepTiming& t, std::size_t contacts);
/// /ssx/sensors: {"<artifact>": {"0": {measurement}, ...}, ...} for every artifact with a measurement
/// measurementJson can write.
std::string sensorsJson(const Environment& env);
/// /ssx/commands: {"<artifact>": {"level": "attitude", "values": [...]}, ...} in set_commands'
/// column order.
std::string commandsJson(const Environment& env);

}  // namespace ssx::detail
