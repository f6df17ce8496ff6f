// A recording read back (ssx/recording.hpp).
#include "record/mcap_reader.hpp"
#include "record/mcap_writer.hpp"
#include "record/pose_codec.hpp"

#include <ssx/error.hpp>
#include <ssx/recording.hpp>

#include <algorithm>
#include <charconv>
#include <iterator>
#include <map>
#include <mutex>
#include <string_view>

#include <zstd.h>

namespace ssx {

struct Recording::Impl {
  detail::McapFile file;
  std::vector<std::string> names;
  std::vector<Nanoseconds> times;
  std::vector<std::size_t> samples;  // indexes into file.messages
  std::mutex mutex;                  // file.data() keeps one chunk: one reader at a time
  std::string scene_xml, scene_label, version;
  std::uint64_t seed = 0;
  struct State {
    Nanoseconds time;
    std::span<const std::byte> data;
    bool zstd;  // compressed (application/x-ssx-state+zstd): by the recorder since 2026-12-07
  };
  std::vector<State> states;
  std::vector<PhysicsSwitch> switches;  // in the file's order (the order made)
  std::map<int, std::vector<std::size_t>> by_channel;  // messageAtOrBefore's: a channel's messages by time (made at first use)
};

namespace {

// a saved state as the recorder writes it: compressed; and the most it may grow when decompressed
// (a state compresses to 1/2-1/5; the bound keeps a corrupted size from asking for terabytes)
constexpr std::string_view kStateZstd = "application/x-ssx-state+zstd";
constexpr unsigned long long kStateMaxRatio = 1024;

[[noreturn]] void notRecording(const std::filesystem::path& file, const std::string& what) {
  throw Error(file.string() + ": not an ssx recording: " + what);
}

}  // namespace

Recording::Recording(const std::filesystem::path& path) : Recording(detail::readMcap(path)) {}

Recording::Recording(std::vector<std::byte> bytes, const std::filesystem::path& label)
    : Recording(detail::parseMcap(std::move(bytes), label)) {}

Recording::Recording(detail::McapFile file) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.file = std::move(file);
  const detail::McapFile& f = m.file;
  const std::filesystem::path& path = f.file;
  if (f.profile != "ssx") notRecording(path, "its profile is '" + f.profile + "', not 'ssx'");
  const auto meta = f.metadata.find("ssx");
  if (meta == f.metadata.end()) notRecording(path, "it has no 'ssx' metadata");
  auto value = [&](const char* key) {
    const auto it = meta->second.find(key);
    return it == meta->second.end() ? std::string() : it->second;
  };
  m.version = value("version");
  m.scene_label = value("scene");
  const std::string seed = value("seed");
  std::from_chars(seed.data(), seed.data() + seed.size(), m.seed);
  if (const auto bodies = f.metadata.find("ssx.bodies"); bodies != f.metadata.end()) {
    const auto it = bodies->second.find("names");
    if (it != bodies->second.end()) {
      std::string_view rest = it->second;
      while (!rest.empty()) {
        const auto end = rest.find('\n');
        m.names.emplace_back(rest.substr(0, end));
        rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
      }
    }
  }
  for (const auto& a : f.attachments) {
    if (a.name == "scene.xml") {
      m.scene_xml.assign(reinterpret_cast<const char*>(a.data.data()), a.data.size());
    } else if (a.name.rfind("state/", 0) == 0) {
      const bool zstd = a.media_type == kStateZstd;
      if (zstd) {
        // (checked here, so that a state asked for later cannot ask for more memory than this)
        const unsigned long long size = ZSTD_getFrameContentSize(a.data.data(), a.data.size());
        if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN || size > kStateMaxRatio * a.data.size())
          notRecording(path, "its saved state '" + a.name + "' is not a zstd frame of a size it can hold (corrupted)");
      }
      m.states.push_back({a.log_time, a.data, zstd});
    } else if (a.name.rfind("physics/", 0) == 0) {
      const std::string text(reinterpret_cast<const char*>(a.data.data()), a.data.size());
      const auto newline = text.find('\n');
      if (newline == std::string::npos || newline == 0 || newline + 1 == text.size())
        notRecording(path, "its attachment '" + a.name + "' is not two engine names on two lines (corrupted)");
      m.switches.push_back({a.log_time, text.substr(0, newline), text.substr(newline + 1)});
    }
  }
  std::sort(m.states.begin(), m.states.end(), [](const auto& a, const auto& b) { return a.time < b.time; });
  std::stable_sort(m.switches.begin(), m.switches.end(), [](const auto& a, const auto& b) { return a.time < b.time; });
  const int channel = f.channelId("/ssx/poses");
  if (channel < 0) notRecording(path, "it has no /ssx/poses channel");
  // every pose sample checked once here, so that reading one later cannot fail: its length, and
  // its time after the one before (the order every reader of a recording relies on)
  const auto at = [&](const detail::McapFile::Message& msg) {
    return path.string() + ": byte " + std::to_string(msg.where) + ": ";
  };
  for (std::size_t i = 0; i < f.messages.size(); ++i) {
    const detail::McapFile::Message& msg = f.messages[i];
    if (msg.channel != channel) continue;
    const std::span<const std::byte> data = f.data(msg);
    if (detail::poseCount(data) != m.names.size() || data.size() != detail::poseBytes(m.names.size()))
      throw Error(at(msg) + "a pose sample at " + std::to_string(toSeconds(msg.log_time)) + " s of " +
                  std::to_string(data.size()) + " bytes, holding " + std::to_string(detail::poseCount(data)) +
                  " bodies; the recording names " + std::to_string(m.names.size()) + ", which take " +
                  std::to_string(detail::poseBytes(m.names.size())) + " bytes (corrupted)");
    if (!m.times.empty() && msg.log_time <= m.times.back())
      throw Error(at(msg) + "a pose sample at " + std::to_string(toSeconds(msg.log_time)) +
                  " s follows one at " + std::to_string(toSeconds(m.times.back())) +
                  " s: its times go back or repeat (a state restored to an earlier time while recording), "
                  "which ssx cannot play; record each episode into a file of its own");
    m.times.push_back(msg.log_time);
    m.samples.push_back(i);
  }
}

Recording::~Recording() = default;
Recording::Recording(Recording&&) noexcept = default;
Recording& Recording::operator=(Recording&&) noexcept = default;

const std::vector<std::string>& Recording::names() const noexcept { return impl_->names; }
const std::vector<Nanoseconds>& Recording::times() const noexcept { return impl_->times; }
const std::string& Recording::sceneXml() const noexcept { return impl_->scene_xml; }
const std::string& Recording::sceneLabel() const noexcept { return impl_->scene_label; }
const std::string& Recording::version() const noexcept { return impl_->version; }
std::uint64_t Recording::seed() const noexcept { return impl_->seed; }
bool Recording::complete() const noexcept { return impl_->file.complete; }
std::uint64_t Recording::size() const noexcept { return impl_->file.size; }

std::vector<float> Recording::positions(std::size_t k) const {
  std::vector<float> out;
  const std::lock_guard lock(impl_->mutex);
  detail::decodePoses(impl_->file.data(impl_->file.messages[impl_->samples.at(k)]), &out, nullptr);
  return out;
}

std::vector<float> Recording::orientations(std::size_t k) const {
  std::vector<float> out;
  const std::lock_guard lock(impl_->mutex);
  detail::decodePoses(impl_->file.data(impl_->file.messages[impl_->samples.at(k)]), nullptr, &out);
  return out;
}

std::vector<PhysicsSwitch> Recording::physicsSwitches() const { return impl_->switches; }

std::vector<Nanoseconds> Recording::stateTimes() const {
  std::vector<Nanoseconds> out;
  for (const auto& s : impl_->states) out.push_back(s.time);
  return out;
}

std::vector<std::byte> Recording::stateAtOrBefore(Nanoseconds time, Nanoseconds* at) const {
  const Impl::State* best = nullptr;
  for (const auto& s : impl_->states)
    if (s.time <= time) best = &s;
  if (best == nullptr)
    throw Error(
        impl_->file.file.string() + ": no saved state at or before " + std::to_string(toSeconds(time)) + " s (" +
        (impl_->states.empty() ? std::string("it has none")
                               : "the first is at " + std::to_string(toSeconds(impl_->states.front().time)) + " s") +
        ")");
  if (at != nullptr) *at = best->time;
  if (!best->zstd) return {best->data.begin(), best->data.end()};
  std::vector<std::byte> out(ZSTD_getFrameContentSize(best->data.data(), best->data.size()));
  const std::size_t got = ZSTD_decompress(out.data(), out.size(), best->data.data(), best->data.size());
  if (ZSTD_isError(got) || got != out.size())
    throw Error(impl_->file.file.string() + ": the saved state at " + std::to_string(toSeconds(best->time)) +
                " s does not decompress (corrupted)");
  return out;
}

void completeRecording(const std::filesystem::path& damaged, const std::filesystem::path& out) {
  detail::rewriteMcap(detail::readMcap(damaged), out);
}

std::vector<std::pair<std::string, std::uint64_t>> Recording::channels() const {
  std::vector<std::pair<std::string, std::uint64_t>> out;
  std::map<std::uint16_t, std::uint64_t> counts;
  for (const auto& msg : impl_->file.messages) ++counts[msg.channel];
  for (const auto& [id, c] : impl_->file.channels) out.emplace_back(c.topic, counts[id]);
  return out;
}

}  // namespace ssx

namespace ssx {

std::vector<std::pair<Nanoseconds, std::string>> Recording::messages(const std::string& topic) const {
  const detail::McapFile& f = impl_->file;
  const int channel = f.channelId(topic);
  if (channel < 0) {
    std::string there;
    for (const auto& [id, c] : f.channels) there += (there.empty() ? "" : ", ") + c.topic;
    throw Error(f.file.string() + ": no channel '" + topic + "' (there are: " + there + ")");
  }
  std::vector<std::pair<Nanoseconds, std::string>> out;
  const std::lock_guard lock(impl_->mutex);
  for (const auto& msg : f.messages)
    if (msg.channel == channel) {
      const std::span<const std::byte> data = f.data(msg);
      out.emplace_back(msg.log_time, std::string(reinterpret_cast<const char*>(data.data()), data.size()));
    }
  return out;
}

std::optional<std::pair<Nanoseconds, std::string>> Recording::messageAtOrBefore(const std::string& topic,
                                                                               Nanoseconds time) const {
  const detail::McapFile& f = impl_->file;
  const int channel = f.channelId(topic);
  if (channel < 0) return std::nullopt;
  const std::lock_guard lock(impl_->mutex);
  auto [it, made] = impl_->by_channel.try_emplace(channel);
  std::vector<std::size_t>& index = it->second;
  if (made) {
    for (std::size_t k = 0; k < f.messages.size(); ++k)
      if (f.messages[k].channel == channel) index.push_back(k);
    std::stable_sort(index.begin(), index.end(),
                     [&f](std::size_t a, std::size_t b) { return f.messages[a].log_time < f.messages[b].log_time; });
  }
  // the first logged after `time`, then the one before it
  const auto after = std::upper_bound(index.begin(), index.end(), time,
                                      [&f](Nanoseconds t, std::size_t k) { return t < f.messages[k].log_time; });
  if (after == index.begin()) return std::nullopt;
  const detail::McapFile::Message& msg = f.messages[*std::prev(after)];
  const std::span<const std::byte> data = f.data(msg);
  return std::pair{msg.log_time, std::string(reinterpret_cast<const char*>(data.data()), data.size())};
}

std::string Recording::encoding(const std::string& topic) const {
  const detail::McapFile& f = impl_->file;
  const int channel = f.channelId(topic);
  return channel < 0 ? std::string() : f.channels.at(static_cast<std::uint16_t>(channel)).encoding;
}

}  // namespace ssx
