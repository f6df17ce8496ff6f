#pragma once
// The JSON channels a run offers beside its poses, the same in a recording (Recorder) and live
// (the foxglove extension), so that one Foxglove layout serves both:
// - /scene (foxglove.SceneUpdate): every artifact's shapes, in the frame of the body it moves with;
// - /ssx/timing (ssx.StepTiming): one step's wall-clock cost;
// - /ssx/sensors (ssx.Sensors): each artifact's latest measurements;
// - /ssx/commands (ssx.Commands): each commandable robot's current command.
// Each function reads the environment: call it on the stepping thread (or while it stands).

#include <ssx/recording.hpp>
#include <ssx/timing.hpp>
#include <ssx/types.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace ssx {
class Environment;
}

namespace ssx::detail {

/// JSON Schemas of the messages below (only the fields written).
extern const char* const kTimingSchema;
extern const char* const kSensorsSchema;
extern const char* const kCommandsSchema;

/// foxglove.SceneUpdate of a running environment: each render tree in the frame of the recorded
/// body (`bodies`, as recordedBodies gives them) it moves with, or of the world.
std::string runSceneUpdate(const Environment& env, const std::vector<RecordedBody>& bodies);
/// /ssx/timing: one step's cost, ms, and the physics engine's contact points in it.
std::string timingJson(const StepTiming& t, std::size_t contacts);
/// /ssx/sensors: {"<artifact>": {"0": {measurement}, ...}, ...} for every artifact with a measurement
/// measurementJson can write.
std::string sensorsJson(const Environment& env);
/// /ssx/commands: {"<artifact>": {"level": "attitude", "values": [...]}, ...} in set_commands'
/// column order.
std::string commandsJson(const Environment& env);

}  // namespace ssx::detail
