// The JSON channels a run offers (record/run_channels.hpp).
#include "record/run_channels.hpp"

#include "base/json.hpp"
#include "record/foxglove.hpp"

#include <ssx/command.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>

#include <utility>

namespace ssx::detail {

const char* const kTimingSchema =
    R"j({"title":"ssx.StepTiming","description":"one step's wall-clock cost, ms, and how late it ended (real-time runs)","type":"object","properties":{)j"
    R"j("step":{"type":"integer"},"contacts":{"type":"integer"},"total_ms":{"type":"number"},"physics_ms":{"type":"number"},"snapshot_ms":{"type":"number"},)j"
    R"j("sensors_ms":{"type":"number"},"drivers_ms":{"type":"number"},"render_ms":{"type":"number"},"late_ms":{"type":"number"}}})j";
const char* const kSensorsSchema =
    R"j({"title":"ssx.Sensors","description":"each artifact's latest measurements by sensor index: imu (accelerometer m/s^2, gyroscope rad/s, sensor frame), )j"
    R"j(pose (position m, orientation w x y z, velocities world frame), range (detections: seen, obstacle, relative m, distance m)","type":"object",)j"
    R"j("additionalProperties":{"type":"object","additionalProperties":{"type":"object","properties":{"kind":{"type":"string"},"stamp":{"type":"number"}}}}})j";

const char* const kCommandsSchema =
    R"j({"title":"ssx.Commands","description":"each commandable robot's current command: its level (position, velocity, attitude, rates, rotors) and values in the column order of Python's set_commands","type":"object",)j"
    R"j("additionalProperties":{"type":"object","properties":{"level":{"type":"string"},"values":{"type":"array","items":{"type":"number"}}}}})j";

std::string runSceneUpdate(const Environment& env, const std::vector<RecordedBody>& bodies) {
  std::vector<SceneShape> shapes;
  auto add = [&](auto& self, const RenderNodeSpec& spec, const std::string& frame, const Pose& parent) -> void {
    const Pose pose = parent * spec.pose;
    shapes.push_back({frame, &spec, pose});
    for (const auto& c : spec.children) self(self, c, frame, pose);
  };
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    const Artifact& a = env.artifact(i);
    for (const auto& tree : a.renderRoots()) {
      const PhysicNode* follow = tree->follow.empty() ? nullptr : a.node(tree->follow);
      const RecordedBody* body = follow != nullptr ? recordedBodyOf(bodies, *follow) : nullptr;
      if (follow == nullptr) {
        add(add, *tree, kWorldFrame, a.placement());
      } else if (body == nullptr) {  // a static root: where it is now, for good
        add(add, *tree, kWorldFrame, follow->pose());
      } else {  // the followed node in the frame of its body's head (both fixed in that body)
        add(add, *tree, body->name, body->node->poseInBody().inverse() * follow->poseInBody());
      }
    }
  }
  return sceneUpdate(env.time(), shapes);
}

std::string timingJson(const StepTiming& t, std::size_t contacts) {
  std::string out = R"({"step":)" + std::to_string(t.step) + R"(,"contacts":)" + std::to_string(contacts);
  const std::pair<const char*, Nanoseconds> fields[] = {{"total_ms", t.total},     {"physics_ms", t.physics},
                                                        {"snapshot_ms", t.snapshot}, {"sensors_ms", t.sensors},
                                                        {"drivers_ms", t.drivers}, {"render_ms", t.render},
                                                        {"late_ms", t.lateness}};
  for (const auto& [name, value] : fields) {
    out += ",\"";
    out += name;
    out += "\":";
    appendNumber(out, static_cast<double>(value) / 1e6);
  }
  return out + "}";
}

std::string sensorsJson(const Environment& env) {
  std::string out = "{";
  bool first_artifact = true;
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    const Artifact& a = env.artifact(i);
    std::string body;
    for (std::size_t k = 0; k < a.sensorCount(); ++k) {
      const std::string m = measurementJson(a.sensor(k).latest(), env);
      if (m.empty()) continue;
      if (!body.empty()) body += ',';
      body += '"' + std::to_string(k) + "\":" + m;
    }
    if (body.empty()) continue;
    if (!first_artifact) out += ',';
    first_artifact = false;
    appendString(out, a.name());
    out += ":{" + body + "}";
  }
  return out + "}";
}

std::string commandsJson(const Environment& env) {
  std::string out = "{";
  bool first = true;
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    const Artifact& a = env.artifact(i);
    const auto* commandable = dynamic_cast<const CommandInterface*>(a.driver());
    if (commandable == nullptr) continue;
    if (!first) out += ',';
    first = false;
    appendString(out, a.name());
    out += ':' + commandJson(commandable->currentCommand());
  }
  return out + "}";
}

}  // namespace ssx::detail
