#pragma once
// What a page is shown of a robot selected in a recording played (ssx replay --view): its
// velocities from the recorded poses, and, when the run recorded them (--record-channels sensors,
// commands), its command and its sensors' measurements as they were at the sample shown, in the
// live viewer's form ({"body","name","v","w","command","sensors"}: the page's panel and plots
// read both alike). Not thread-safe: the viewer's playback thread alone uses it.
#include <ssx/recording.hpp>

#include <cstddef>
#include <memory>
#include <string>

namespace ssx::viewer {

class ReplayDetails {
 public:
  /// `recording` must outlive this.
  explicit ReplayDetails(const Recording& recording);
  ~ReplayDetails();
  ReplayDetails(const ReplayDetails&) = delete;
  ReplayDetails& operator=(const ReplayDetails&) = delete;

  /// The details of recorded body `body` (its index in recording.names()), whose artifact is
  /// `artifact`, at sample `k`: a JSON object. Velocities from sample k-1 to k (k+1 for the first;
  /// zero for a recording of one sample), in the world frame; "command" null and "sensors" empty
  /// when the recording has none for the artifact (each sensor named by its kind).
  std::string json(std::size_t k, std::size_t body, const std::string& artifact);

  /// Whether the recording holds commands, sensors.
  bool hasCommands() const noexcept { return has_commands_; }
  bool hasSensors() const noexcept { return has_sensors_; }

 private:
  struct Cache;
  const Recording& recording_;
  bool has_commands_ = false, has_sensors_ = false;
  std::unique_ptr<Cache> cache_;
};

}  // namespace ssx::viewer
