// The JSON channels a run offers (record/run_channels.hpp).
#include "record/run_channels.hpp"

#include "base/json.hpp"
#include "base/measurement_json.hpp"
#include "record/foxglove.hpp"

#include <ssx/command.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>

#include <algorithm>
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

const char* const kContactsSchema =
    R"j({"title":"ssx.Contacts","description":"the contacts of a step: per pair of bodies (or a body and a static artifact), the artifacts, the deepest point (m, world), the normal from b to a and the normal impulse (N s)","type":"object","properties":{"contacts":{"type":"array","items":{"type":"object","properties":{)j"
    R"j("a":{"type":"string"},"b":{"type":"string"},"position":{"type":"array","items":{"type":"number"}},"normal":{"type":"array","items":{"type":"number"}},"impulse":{"type":"number"}}}}}})j";

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

void RunSample::takeSensors(const Environment& env) { take(env, kAllArtifacts); }

void RunSample::takeSensorsOf(const Environment& env, std::size_t artifact) { take(env, artifact); }

void RunSample::take(const Environment& env, std::size_t artifact) {
  if (sources_of_ != &env || sources_artifact_ != artifact) {
    sources_.clear();
    std::size_t counts[3] = {0, 0, 0};
    const std::size_t begin = artifact == kAllArtifacts ? 0 : artifact;
    const std::size_t end =
        artifact == kAllArtifacts ? env.artifactCount() : std::min(artifact + 1, env.artifactCount());
    for (std::size_t i = begin; i < end; ++i) {
      const Artifact& a = env.artifact(i);
      for (std::size_t k = 0; k < a.sensorCount(); ++k) {
        const Measurement& m = a.sensor(k).latest();
        Kind kind = Kind::Imu;
        if (dynamic_cast<const ImuMeasurement*>(&m) != nullptr)
          kind = Kind::Imu;
        else if (dynamic_cast<const PoseMeasurement*>(&m) != nullptr)
          kind = Kind::Pose;
        else if (dynamic_cast<const RangeMeasurement*>(&m) != nullptr)
          kind = Kind::Range;
        else
          continue;
        sources_.push_back({i, k, kind, counts[static_cast<int>(kind)]++, &m});
      }
    }
    sources_of_ = &env;
    sources_artifact_ = artifact;
    imus_.resize(counts[0]);
    poses_.resize(counts[1]);
    ranges_.resize(counts[2]);
  }
  // one pass in the order of the sensors, each copied into its kind's vector (a range sensor's
  // detections into the vector's room: no allocation once grown); the measurement a few sources
  // ahead fetched while this one is copied (thousands of robots: each is a cache miss)
  constexpr std::size_t kAhead = 8;
  for (std::size_t k = 0; k < sources_.size(); ++k) {
    if (k + kAhead < sources_.size()) __builtin_prefetch(sources_[k + kAhead].latest);
    const Source& source = sources_[k];
    switch (source.kind) {
      case Kind::Imu:
        imus_[source.slot] = static_cast<const ImuMeasurement&>(*source.latest);
        break;
      case Kind::Pose:
        poses_[source.slot] = static_cast<const PoseMeasurement&>(*source.latest);
        break;
      case Kind::Range:
        ranges_[source.slot] = static_cast<const RangeMeasurement&>(*source.latest);
        break;
    }
  }
}

const Measurement& RunSample::copyOf(const Source& source) const {
  switch (source.kind) {
    case Kind::Imu:
      return imus_[source.slot];
    case Kind::Pose:
      return poses_[source.slot];
    case Kind::Range:
      break;
  }
  return ranges_[source.slot];
}

void RunSample::takeCommands(const Environment& env) {
  if (commandables_of_ != &env) {  // (drivers, like sensors, stay the same while it runs)
    commandables_.clear();
    for (std::size_t i = 0; i < env.artifactCount(); ++i)
      if (const auto* commandable = dynamic_cast<const CommandInterface*>(env.artifact(i).driver()))
        commandables_.emplace_back(i, commandable);
    commandables_of_ = &env;
    commands_.resize(commandables_.size());
  }
  constexpr std::size_t kAhead = 8;
  for (std::size_t k = 0; k < commandables_.size(); ++k) {
    if (k + kAhead < commandables_.size()) __builtin_prefetch(commandables_[k + kAhead].second);
    commands_[k].first = commandables_[k].first;
    commands_[k].second = commandables_[k].second->currentCommand();
  }
}

// one artifact's sensors from source k on, as {"0": {measurement}, ...}; k moves past them
void RunSample::appendArtifact(std::string& out, const Environment& env, std::size_t& k) const {
  const std::size_t artifact = sources_[k].artifact;
  out += '{';
  for (bool first = true; k < sources_.size() && sources_[k].artifact == artifact; ++k, first = false) {
    const Source& source = sources_[k];
    if (!first) out += ',';
    out += '"';
    out += std::to_string(source.index);
    out += "\":";
    appendMeasurementJson(out, copyOf(source), env);
  }
  out += '}';
}

std::string RunSample::sensorsJson(const Environment& env) const {
  std::string out = "{";
  out.reserve(sensors_json_size_);
  for (std::size_t k = 0; k < sources_.size();) {
    if (out.size() > 1) out += ',';
    appendString(out, env.artifact(sources_[k].artifact).name());
    out += ':';
    appendArtifact(out, env, k);
  }
  out += '}';
  sensors_json_size_ = out.size() + out.size() / 8;
  return out;
}

std::string RunSample::artifactSensorsJson(const Environment& env) const {
  if (sources_.empty()) return "{}";
  std::string out;
  std::size_t k = 0;
  appendArtifact(out, env, k);
  return out;
}

const ImuMeasurement* RunSample::firstImu() const {
  for (const Source& source : sources_)
    if (source.kind == Kind::Imu) return &imus_[source.slot];
  return nullptr;
}

std::string RunSample::commandsJson(const Environment& env) const {
  std::string out = "{";
  for (const auto& [artifact, command] : commands_) {
    if (out.size() > 1) out += ',';
    appendString(out, env.artifact(artifact).name());
    out += ':' + commandJson(command);
  }
  return out + "}";
}

void RunSample::takeContacts(const Environment& env) { contacts_.assign(env.contacts().begin(), env.contacts().end()); }

std::string RunSample::contactsJson(const Environment& env) const {
  std::string out = R"({"contacts":[)";
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    const EngineContact& c = contacts_[k];
    out += k == 0 ? R"({"a":)" : R"(,{"a":)";
    appendString(out, env.bodyOwner(c.body_a).name());
    out += R"(,"b":)";
    appendString(out, env.contactOther(c).name());
    for (const auto& [name, v] : {std::pair<const char*, const Vec3*>{"position", &c.position}, {"normal", &c.normal}}) {
      out += ",\"";
      out += name;
      out += "\":[";
      for (int i = 0; i < 3; ++i) {
        if (i > 0) out += ',';
        appendNumber(out, (*v)[i]);
      }
      out += ']';
    }
    out += R"(,"impulse":)";
    appendNumber(out, c.impulse);
    out += '}';
  }
  return out + "]}";
}

std::string sensorsJson(const Environment& env) {
  RunSample sample;
  sample.takeSensors(env);
  return sample.sensorsJson(env);
}

std::string commandsJson(const Environment& env) {
  RunSample sample;
  sample.takeCommands(env);
  return sample.commandsJson(env);
}

}  // namespace ssx::detail
