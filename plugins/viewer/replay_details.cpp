// The details of a recorded robot (replay_details.hpp). The recording's JSON channels are read with
// nlohmann/json: of a message (every artifact's measurements, megabytes at 10,000 robots) only the
// selected artifact's member is built, and a message is read once while the page stays on it.
#include "replay_details.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <utility>
#include <vector>

namespace ssx::viewer {

namespace {

// The member `key` of a message's top-level object (null when it has none or the text is not JSON):
// the parser discards every other member as it reads them.
nlohmann::json memberOf(const std::string& text, const std::string& key) {
  const nlohmann::json::parser_callback_t keep = [&key](int depth, nlohmann::json::parse_event_t event,
                                                        nlohmann::json& parsed) {
    return !(depth == 1 && event == nlohmann::json::parse_event_t::key && parsed != key);
  };
  nlohmann::json whole = nlohmann::json::parse(text, keep, false);
  if (!whole.is_object()) return nullptr;
  const auto it = whole.find(key);
  return it == whole.end() ? nlohmann::json() : std::move(*it);
}

}  // namespace

struct ReplayDetails::Cache {
  // per channel: the message last read (its time) and the artifact's member of it
  struct Member {
    std::optional<Nanoseconds> time;
    std::string artifact;
    nlohmann::json value;
  };
  Member commands, sensors;

  const nlohmann::json& lookUp(Member& m, const Recording& r, const char* topic, Nanoseconds t,
                               const std::string& artifact) {
    const auto message = r.messageAtOrBefore(topic, t);
    if (!message) {
      m = Member{};
      return m.value;
    }
    if (m.time != message->first || m.artifact != artifact) {
      m.time = message->first;
      m.artifact = artifact;
      m.value = memberOf(message->second, artifact);
    }
    return m.value;
  }
};

ReplayDetails::ReplayDetails(const Recording& recording) : recording_(recording), cache_(std::make_unique<Cache>()) {
  for (const auto& [topic, count] : recording.channels()) {
    has_commands_ |= topic == "/ssx/commands" && count > 0;
    has_sensors_ |= topic == "/ssx/sensors" && count > 0;
  }
}

ReplayDetails::~ReplayDetails() = default;

std::string ReplayDetails::json(std::size_t k, std::size_t body, const std::string& artifact) {
  const std::vector<Nanoseconds>& times = recording_.times();
  nlohmann::json out;
  out["body"] = body;
  out["name"] = recording_.names().at(body);
  // the velocities over the interval that ends at this sample (begins, for the first)
  Vec3 v = Vec3::Zero(), w = Vec3::Zero();
  if (times.size() > 1) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = k == 0 ? 1 : k;
    const double dt = toSeconds(times[b] - times[a]);
    const std::vector<float> pa = recording_.positions(a), pb = recording_.positions(b);
    const std::vector<float> qa = recording_.orientations(a), qb = recording_.orientations(b);
    for (int i = 0; i < 3; ++i) v[i] = (double(pb[3 * body + i]) - double(pa[3 * body + i])) / dt;
    const auto quat = [body](const std::vector<float>& q) {
      return Quat(q[4 * body], q[4 * body + 1], q[4 * body + 2], q[4 * body + 3]).normalized();
    };
    // the turn from a to b in the world frame, the shorter way round
    Quat turn = quat(qb) * quat(qa).conjugate();
    if (turn.w() < 0) turn.coeffs() = -turn.coeffs();
    const double s = turn.vec().norm();
    if (s > 0) w = turn.vec() / s * (2 * std::atan2(s, turn.w()) / dt);
  }
  out["v"] = {v.x(), v.y(), v.z()};
  out["w"] = {w.x(), w.y(), w.z()};
  out["recorded"] = true;
  const Nanoseconds t = times.at(k);
  out["command"] = has_commands_ ? cache_->lookUp(cache_->commands, recording_, "/ssx/commands", t, artifact) : nullptr;
  out["sensors"] = nlohmann::json::array();
  if (has_sensors_) {
    const nlohmann::json& sensors = cache_->lookUp(cache_->sensors, recording_, "/ssx/sensors", t, artifact);
    if (sensors.is_object()) {
      // by sensor index, as the artifact lists them
      std::vector<std::pair<long, const nlohmann::json*>> in_order;
      for (const auto& [index, m] : sensors.items())
        if (m.is_object()) in_order.emplace_back(std::strtol(index.c_str(), nullptr, 10), &m);  // (a file's own)
      std::sort(in_order.begin(), in_order.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      for (const auto& [index, m] : in_order) {
        nlohmann::json shown = *m;
        const auto kind = m->find("kind");
        shown["sensor"] = kind != m->end() && kind->is_string() ? *kind : nlohmann::json("sensor");
        out["sensors"].push_back(std::move(shown));
      }
    }
  }
  return out.dump();
}

}  // namespace ssx::viewer
