#pragma once
// A frame of the viewer's stream (docs/viewer.md, "What a page receives"), little-endian:
// uint32 magic 0x46585353 ("SSXF"), uint32 N, float64 simulated time (s), float32 real-time factor,
// uint32 late steps, uint64 step (or sample); N x float32 x, y, z, qx, qy, qz, qw; uint32 L and L
// bytes of JSON (the trailer).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace ssx::viewer {

inline constexpr std::uint32_t kFrameMagic = 0x46585353;
inline constexpr std::size_t kFrameHeaderBytes = 32, kFramePoseBytes = 28;

struct FrameHeader {
  double time = 0;          ///< simulated s
  float rate = 0;           ///< real-time factor (a replay: its speed, 0 paused)
  std::uint32_t late = 0;   ///< late steps so far
  std::uint64_t step = 0;   ///< the step, or the recording's sample
};

/// Starts a frame of `n` poses in `out` (its old bytes overwritten, its buffer kept) and returns
/// where the poses go: 7 floats each, x y z qx qy qz qw.
float* beginFrame(std::vector<std::uint8_t>& out, const FrameHeader& header, std::uint32_t n);
/// Ends the frame begun with `n` poses: the trailer's length and the trailer.
void endFrame(std::vector<std::uint8_t>& out, std::uint32_t n, std::string_view trailer);

/// What the server says of a step's velocity command that came from a page: the page's own number
/// and time stamp ("page", "sent" in its message), and how long the command waited for its step.
struct CommandEcho {
  double page = 0, sent = -1, waited_ms = 0;  ///< sent < 0: no command to echo
};

/// The trailer: {"run":{"factor":F,"paused":B}} with "command":{...} when `echo` has one and
/// "details":DETAILS (a JSON array) when not empty.
std::string trailerJson(double factor, bool paused, const std::string& details, const CommandEcho& echo = {});

/// When frames go out, at most one a `period`, to a caller that asks at its own ticks (a run's
/// steps, a page's sending thread): due on a schedule one period apart, so that ticks of 20 ms
/// give 30 frames a second at 30 Hz (waiting a whole period after each frame sent gives 25); a
/// frame sent more than a period late starts the schedule again (no burst after a pause or a
/// slow stretch).
class FramePacer {
 public:
  using Clock = std::chrono::steady_clock;
  explicit FramePacer(std::chrono::duration<double> period = {})
      : period_(std::chrono::duration_cast<Clock::duration>(period)) {}
  /// Whether a frame is due at `now` (the first always is).
  bool due(Clock::time_point now) const { return !started_ || now >= next_; }
  /// When the next frame is due (after a first one).
  Clock::time_point next() const { return next_; }
  /// A frame went out at `now`: the next is due a period after this one was.
  void sent(Clock::time_point now) {
    next_ = started_ && now - next_ < period_ ? next_ + period_ : now + period_;
    started_ = true;
  }

 private:
  Clock::duration period_;
  Clock::time_point next_{};
  bool started_ = false;
};

/// Appends a number (6 significant digits; 0 for NaN and infinities) or a JSON string.
void appendNumber(std::string& out, double v);
void appendString(std::string& out, std::string_view s);

}  // namespace ssx::viewer
