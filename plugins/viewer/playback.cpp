// The clock of a recording played on the page (playback.hpp).
#include "playback.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace ssx::viewer {

Playback::Playback(std::vector<Nanoseconds> times) : times_(std::move(times)) {
  if (times_.empty()) times_.push_back(0);
  time_ = times_.front();
}

void Playback::resume() noexcept {
  if (sample_ + 1 >= times_.size()) seek(times_.front());
  paused_ = false;
}

void Playback::stepOnce() noexcept {
  if (!paused_ || sample_ + 1 >= times_.size()) return;
  time_ = times_[++sample_];
}

bool Playback::setSpeed(double speed) noexcept {
  if (!(speed >= kMinSpeed && speed <= kMaxSpeed)) return false;
  speed_ = speed;
  return true;
}

void Playback::seek(Nanoseconds t) noexcept {
  time_ = std::clamp(t, times_.front(), times_.back());
  settle();
}

void Playback::advance(double wall_seconds) noexcept {
  if (paused_ || !(wall_seconds > 0)) return;
  const double step = std::min(wall_seconds * speed_ * 1e9, static_cast<double>(times_.back() - time_));
  time_ += static_cast<Nanoseconds>(std::llround(step));
  settle();
  if (sample_ + 1 >= times_.size()) paused_ = true;  // held at the end
}

void Playback::settle() noexcept {
  sample_ = static_cast<std::size_t>(std::upper_bound(times_.begin(), times_.end(), time_) - times_.begin()) - 1;
}

}  // namespace ssx::viewer
