#include <ssx/error.hpp>
#include <ssx/run_files.hpp>
#include <ssx/timing.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <sstream>

namespace ssx {

namespace {

// nearest-rank percentile of sorted values, in milliseconds
double percentileMs(const std::vector<Nanoseconds>& sorted, double p) {
  if (sorted.empty()) return 0.0;
  const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(sorted.size())));
  const std::size_t i = std::min(sorted.size() - 1, rank == 0 ? 0 : rank - 1);
  return static_cast<double>(sorted[i]) * 1e-6;
}

double medianMs(std::vector<Nanoseconds> values) {
  std::sort(values.begin(), values.end());
  return percentileMs(values, 50.0);
}

}  // namespace

TimingRecorder::TimingRecorder(std::size_t capacity) { ring_.reserve(std::max<std::size_t>(2, capacity)); }

void TimingRecorder::add(const StepTiming& sample) noexcept {
  // until the ring is full the next sample goes at its end (head_ is its size): within the room
  // reserved, so without allocating; then over the oldest. The inline readers' index arithmetic
  // over ring_.size() holds either way
  if (ring_.size() < ring_.capacity())
    ring_.push_back(sample);
  else
    ring_[head_] = sample;
  head_ = (head_ + 1) % ring_.capacity();
  size_ = std::min(size_ + 1, ring_.capacity());
  ++recorded_;
}

void TimingRecorder::clear() noexcept {
  ring_.clear();  // (the room stays)
  head_ = size_ = 0;
  recorded_ = 0;
}

std::vector<StepTiming> TimingRecorder::samples() const {
  std::vector<StepTiming> out;
  out.reserve(size_);
  for (std::size_t i = 0; i < size_; ++i) out.push_back((*this)[i]);
  return out;
}

TimingSummary TimingRecorder::summary(Nanoseconds wall, Nanoseconds simulated, std::int64_t since) const {
  TimingSummary s;
  // the kept samples are the recorded ones numbered recorded_ - size_ ... recorded_ - 1
  const std::int64_t oldest = recorded_ - static_cast<std::int64_t>(size_);
  const std::size_t first = static_cast<std::size_t>(std::clamp<std::int64_t>(since - oldest, 0, static_cast<std::int64_t>(size_)));
  const std::size_t n = size_ - first;
  s.steps = std::max<std::int64_t>(0, recorded_ - std::max<std::int64_t>(since, 0));
  s.timed_steps = static_cast<std::int64_t>(n);
  s.wall_s = toSeconds(wall);
  s.simulated_s = toSeconds(simulated);
  s.realtime_factor = wall > 0 ? s.simulated_s / s.wall_s : 0.0;
  if (n == 0) return s;
  std::vector<Nanoseconds> total, physics, sensors, drivers, render;
  total.reserve(n);
  double sum = 0;
  Nanoseconds max_late = 0;
  for (std::size_t i = first; i < size_; ++i) {
    const StepTiming* it = &(*this)[i];
    total.push_back(it->total);
    physics.push_back(it->physics);
    sensors.push_back(it->sensors);
    drivers.push_back(it->drivers);
    render.push_back(it->render);
    sum += static_cast<double>(it->total);
    if (it->lateness > 0) ++s.overruns;
    max_late = std::max(max_late, it->lateness);
  }
  std::sort(total.begin(), total.end());
  s.median_ms = percentileMs(total, 50);
  s.p95_ms = percentileMs(total, 95);
  s.p99_ms = percentileMs(total, 99);
  s.max_ms = static_cast<double>(total.back()) * 1e-6;
  s.mean_ms = sum / static_cast<double>(n) * 1e-6;
  s.physics_median_ms = medianMs(std::move(physics));
  s.sensors_median_ms = medianMs(std::move(sensors));
  s.drivers_median_ms = medianMs(std::move(drivers));
  s.render_median_ms = medianMs(std::move(render));
  s.max_lateness_ms = static_cast<double>(max_late) * 1e-6;
  return s;
}

std::string TimingSummary::str() const {
  // the ring keeps the newest steps' times: say so when the run made more
  const std::string timed_note =
      timed_steps < steps ? " (of the newest " + std::to_string(timed_steps) + " steps)" : std::string();
  char buf[896];
  int used = 0;
  if (timed_steps == 0 && steps > 0)  // an environment that keeps no timing (timing_samples = 0)
    used = std::snprintf(buf, sizeof buf,
                         "steps %lld, simulated %.3f s in %.3f s wall (real-time factor %.3f)\n"
                         "step times not kept (EnvironmentSettings::timing_samples = 0)\n"
                         "overruns %lld (max lateness %.3f ms)",
                         static_cast<long long>(steps), simulated_s, wall_s, realtime_factor,
                         static_cast<long long>(overruns), max_lateness_ms);
  else
    used = std::snprintf(buf, sizeof buf,
                         "steps %lld, simulated %.3f s in %.3f s wall (real-time factor %.3f)\n"
                         "step time ms%s: median %.4f  p95 %.4f  p99 %.4f  max %.4f  mean %.4f\n"
                         "phase medians ms: physics %.4f  sensors %.4f  drivers %.4f  render %.4f\n"
                         "overruns %lld (max lateness %.3f ms)",
                         static_cast<long long>(steps), simulated_s, wall_s, realtime_factor, timed_note.c_str(),
                         median_ms, p95_ms, p99_ms, max_ms, mean_ms, physics_median_ms, sensors_median_ms,
                         drivers_median_ms, render_median_ms, static_cast<long long>(overruns), max_lateness_ms);
  // (known only for a run's summary: the first late step of a run took long or began late, so a
  // summary without either kind is one made from the samples alone)
  const bool told_apart = overruns_long + overruns_began_late > 0;
  if (told_apart && used > 0 && static_cast<std::size_t>(used) < sizeof buf)
    std::snprintf(buf + used, sizeof buf - static_cast<std::size_t>(used),
                  ": %lld took longer than a step, %lld began late after an on-time step (woken late or held up "
                  "between steps), %lld followed a late step",
                  static_cast<long long>(overruns_long), static_cast<long long>(overruns_began_late),
                  static_cast<long long>(overruns - overruns_long - overruns_began_late));
  return buf;
}

void TimingRecorder::writeCsv(std::ostream& out) const {
  out << "step,physics_ns,snapshot_ns,sensors_ns,drivers_ns,render_ns,total_ns,lateness_ns\n";
  for (std::size_t i = 0; i < size_; ++i) {
    const StepTiming& s = (*this)[i];
    out << s.step << ',' << s.physics << ',' << s.snapshot << ',' << s.sensors << ',' << s.drivers << ',' << s.render
        << ',' << s.total << ',' << s.lateness << '\n';
  }
}

void TimingRecorder::writeCsv(const std::string& path) const {
  std::FILE* f = nullptr;
  try {
    f = openOutputFile(path);  // (locked while written: a second run writing it is refused)
  } catch (const Error& e) {
    throw Error(std::string("cannot write timing CSV: ") + e.what());
  }
  std::ostringstream out;
  writeCsv(out);
  const std::string text = out.str();
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  if (std::fclose(f) != 0 || !written) throw Error("error while writing timing CSV '" + path + "' (disk full?)");
}

}  // namespace ssx
