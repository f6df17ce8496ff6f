#include <ssx/pose_stream.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ssx {

PoseStream::PoseStream(const Settings& settings) : settings_(settings) {
  if (!std::isfinite(settings.horizon) || settings.horizon < 0)
    throw std::invalid_argument("pose stream: the extrapolation horizon must be finite and at least 0 s");
  if (!std::isfinite(settings.timeout) || settings.timeout < 0)
    throw std::invalid_argument("pose stream: the timeout must be finite and at least 0 s");
  if (settings.capacity < 2) throw std::invalid_argument("pose stream: keep at least 2 samples");
}

void PoseStream::add(double stamp, const Pose& pose) {
  if (!std::isfinite(stamp)) throw std::invalid_argument("pose stream: the stamp is not finite");
  if (!pose.position.allFinite() || !pose.orientation.coeffs().allFinite())
    throw std::invalid_argument("pose stream: the pose is not finite");
  if (pose.position.cwiseAbs().maxCoeff() > kMaxCoordinate)
    throw std::invalid_argument("pose stream: a position beyond 1e6 m from the origin (a corrupted sample)");
  const double norm = pose.orientation.norm();
  if (std::abs(norm - 1) > 1e-3)
    throw std::invalid_argument("pose stream: the orientation is not a unit quaternion (norm " + std::to_string(norm) + ")");
  const Sample s{stamp, {pose.position, pose.orientation.normalized()}};
  // (almost always the newest: a search from the back)
  auto it = samples_.end();
  while (it != samples_.begin() && std::prev(it)->stamp > stamp) --it;
  if (it != samples_.begin() && std::prev(it)->stamp == stamp)
    *std::prev(it) = s;
  else
    samples_.insert(it, s);
  while (samples_.size() > settings_.capacity) samples_.pop_front();
}

std::optional<double> PoseStream::newest() const {
  if (samples_.empty()) return std::nullopt;
  return samples_.back().stamp;
}

std::optional<PoseStream::Estimate> PoseStream::dueAt(double t) const {
  // the newest sample stamped at or before t (almost always the newest: a search from the back)
  std::size_t n = samples_.size();
  while (n > 0 && samples_[n - 1].stamp > t) --n;
  if (n == 0) return std::nullopt;
  // the next sample close behind (a replay fed ahead of time): interpolated towards; one further
  // off than the timeout waits until it is due
  if (n < samples_.size() && samples_[n].stamp - samples_[n - 1].stamp <= settings_.timeout)
    return between(samples_[n - 1], samples_[n], t);
  return fromNewest(n, t);
}

std::optional<PoseStream::Estimate> PoseStream::at(double t) const {
  if (samples_.empty()) return std::nullopt;
  if (t >= samples_.back().stamp) return fromNewest(samples_.size(), t);
  // the first sample after t, and the one before it
  const auto after = std::upper_bound(samples_.begin(), samples_.end(), t,
                                      [](double time, const Sample& s) { return time < s.stamp; });
  if (after == samples_.begin()) {  // before the oldest kept
    Estimate e;
    e.pose = after->pose;
    e.age = 0;
    return e;
  }
  return between(*std::prev(after), *after, t);
}

PoseStream::Estimate PoseStream::between(const Sample& a, const Sample& b, double t) {
  Estimate e;
  const double span = b.stamp - a.stamp;
  const double u = (t - a.stamp) / span;
  e.pose.position = a.pose.position + u * (b.pose.position - a.pose.position);
  e.pose.orientation = a.pose.orientation.slerp(u, b.pose.orientation).normalized();
  e.linear_velocity = (b.pose.position - a.pose.position) / span;
  e.angular_velocity = rotationBetween(a.pose.orientation, b.pose.orientation) / span;
  e.age = t - a.stamp;
  return e;
}

// at t, at or past sample n - 1 (the newest of the first n)
PoseStream::Estimate PoseStream::fromNewest(std::size_t n, double t) const {
  Estimate e;
  const Sample& last = samples_[n - 1];
  {
    // past the newest: its velocity from the last two, for at most the horizon, then held
    e.age = t - last.stamp;
    e.extrapolated = t > last.stamp;
    e.lost = e.age > settings_.timeout;
    e.pose = last.pose;
    // (the last two samples' velocity, unless a gap longer than the timeout lies between them: a
    // body found again is not extrapolated from where it was before it was lost)
    if (n >= 2 && last.stamp - samples_[n - 2].stamp <= settings_.timeout) {
      const Sample& before = samples_[n - 2];
      const double dt = last.stamp - before.stamp;
      e.linear_velocity = (last.pose.position - before.pose.position) / dt;
      e.angular_velocity = rotationBetween(before.pose.orientation, last.pose.orientation) / dt;
      const double ahead = std::min(e.age, settings_.horizon);
      if (ahead > 0) {
        e.pose.position += e.linear_velocity * ahead;
        const Vec3 turn = e.angular_velocity * ahead;
        if (turn.norm() > 0)
          e.pose.orientation = (Quat(Eigen::AngleAxisd(turn.norm(), turn.normalized())) * last.pose.orientation).normalized();
      }
      if (e.age > settings_.horizon) e.linear_velocity = e.angular_velocity = Vec3::Zero();  // held
    }
  }
  return e;
}

void PoseStream::saveState(StateWriter& out) const {
  out.write(static_cast<std::uint64_t>(samples_.size()));
  for (const Sample& s : samples_) {
    out.write(s.stamp);
    out.write(s.pose);
  }
}

void PoseStream::loadState(StateReader& in) {
  std::deque<Sample> samples;
  const auto n = in.get<std::uint64_t>();
  if (n > settings_.capacity)
    throw StateError("pose stream: " + std::to_string(n) + " saved samples, this one keeps " +
                     std::to_string(settings_.capacity));
  for (std::uint64_t i = 0; i < n; ++i) {
    Sample s{};
    in.read(s.stamp);
    in.read(s.pose);
    if (!samples.empty() && !(s.stamp > samples.back().stamp)) throw StateError("pose stream: saved samples out of order");
    samples.push_back(s);
  }
  samples_ = std::move(samples);
}

void AgeHistogram::add(double age) {
  if (bins_.empty()) bins_.assign(kBins, 0);
  age = std::max(age, 0.0);
  // (ceil: an age on a bin's upper edge is in that bin, so the edge reported is never below it)
  const double bin = std::ceil(age / kBinSeconds) - 1;
  ++bins_[static_cast<std::size_t>(std::clamp(bin, 0.0, static_cast<double>(kBins - 1)))];
  ++count_;
  max_ = std::max(max_, age);
}

AgeSummary AgeHistogram::summary() const {
  AgeSummary s;
  s.count = count_;
  s.max = max_;
  if (count_ == 0) return s;
  // the upper edge of the bin holding the k-th smallest age (the maximum when it is the last bin)
  auto quantile = [&](std::size_t k) {
    std::size_t seen = 0;
    for (std::size_t b = 0; b < kBins; ++b) {
      seen += bins_[b];
      if (seen > k) return std::min(max_, static_cast<double>(b + 1) * kBinSeconds);
    }
    return max_;
  };
  s.median = quantile(count_ / 2);
  s.p99 = quantile(std::min(count_ - 1, count_ * 99 / 100));
  return s;
}

}  // namespace ssx
