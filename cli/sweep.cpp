// Checks of a sweep before any run, and one run with its metrics (see sweep.hpp).
#include "sweep.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <utility>

namespace ssx::sweep {

namespace {

SceneOptions sceneOptions(const Spec& spec, std::size_t point) {
  SceneOptions o;
  o.plugin_path = spec.plugin_path;
  o.threads = spec.threads;
  o.render_engine = "null";
  o.extensions = spec.extensions;
  o.max_input_bytes = spec.max_input_bytes;
  for (std::size_t i = 0; i < spec.parameters.size(); ++i)
    o.overrides.push_back({spec.parameters[i].target, spec.points[point][i], spec.parameters[i].where});
  return o;
}

std::string oneLine(std::string s) {
  for (std::size_t p; (p = s.find('\n')) != std::string::npos;) s.replace(p, 1, " | ");
  return s;
}

}  // namespace

std::string number(double v) {
  if (!std::isfinite(v)) return "";
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::vector<std::string> csvSplit(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        out.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        out.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

void check(const Spec& spec) {
  std::vector<Diagnostic> found;
  std::set<std::string> reported;
  auto add = [&](Diagnostic d) {
    // what the loader ignores with a warning is an error here: say so
    if (const auto at = d.message.find(" (ignored; "); at != std::string::npos) d.message.replace(at, 11, " (");
    if (reported.insert(d.str()).second) found.push_back(std::move(d));
  };
  for (std::size_t point = 0; point < spec.points.size(); ++point) {
    try {
      Scene scene = loadScene(spec.scene, sceneOptions(spec, point));
      // an attribute the sweep sets must mean something: what the loader would only warn about
      // (an unknown parameter) is an error here
      for (const auto& w : scene.warnings)
        if (w.where.file == spec.file.string()) add({Diagnostic::Severity::Error, w.where, w.message});
      if (point == 0 && found.empty()) {
        if (!spec.duration && !scene.duration)
          add({Diagnostic::Severity::Error, spec.where,
               "<sweep>: no 'duration', and the scene gives no <environment duration>: how long is a run?"});
        // the metrics the plugins publish are known once they are configured
        Environment& env = *scene.environment;
        env.setLogSink([](LogLevel, std::string_view) {});
        env.start();
        std::set<std::string> published{"tracking_error"};
        for (std::size_t a = 0; a < env.artifactCount(); ++a) {
          const Artifact& art = std::as_const(env).artifact(a);
          if (const auto* m = dynamic_cast<const MetricSource*>(art.driver()))
            for (auto& n : m->metricNames()) published.insert(n);
          for (std::size_t s = 0; s < art.sensorCount(); ++s)
            if (const auto* m = dynamic_cast<const MetricSource*>(&art.sensor(s)))
              for (auto& n : m->metricNames()) published.insert(n);
        }
        for (const auto& name : env.extensionNames())
          if (const auto* m = dynamic_cast<const MetricSource*>(env.extension(name)))
            for (auto& n : m->metricNames()) published.insert(n);
        std::string list;
        for (const auto& n : published) list += (list.empty() ? "" : ", ") + n;
        for (const auto& m : spec.metrics) {
          const bool builtin = m.kind == "tracking_error" || m.kind == "min_distance" || m.kind == "contacts" ||
                               m.kind == "state_hash" || m.kind == "settle_time";
          const std::string& name = m.kind == "settle_time" ? m.of : m.kind;
          if ((!builtin || m.kind == "settle_time") && published.count(name) == 0)
            add({Diagnostic::Severity::Error, m.where,
                 "metric '" + name + "': no plugin of this scene publishes it (published: " + list + ")"});
        }
        env.stop();
      }
    } catch (const SceneError& e) {
      for (const auto& d : e.diagnostics())
        if (d.severity == Diagnostic::Severity::Error || d.where.file == spec.file.string())
          add({Diagnostic::Severity::Error, d.where, d.message});
    } catch (const std::exception& e) {
      add({Diagnostic::Severity::Error, {spec.scene.string(), 0}, std::string("starting the scene failed: ") + e.what()});
    }
  }
  // the sweep file's own lines first, in order
  std::stable_sort(found.begin(), found.end(), [&](const Diagnostic& a, const Diagnostic& b) {
    const bool a_own = a.where.file == spec.file.string(), b_own = b.where.file == spec.file.string();
    if (a_own != b_own) return a_own;
    return a_own && a.where.line < b.where.line;
  });
  if (!found.empty()) throw SceneError(std::move(found));
}

// --- one run --------------------------------------------------------------------------------

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// what one run collects while it steps
struct Collector {
  const Spec& spec;
  std::vector<const Artifact*> robots;          // dynamic roots
  std::vector<const Artifact*> trackers;        // set-point drivers
  std::vector<const SetpointInterface*> setpoints;
  std::vector<const MetricSource*> sources;
  std::vector<double> track_sum, track_max, nearest;
  std::vector<std::int64_t> track_n;
  double min_distance = std::numeric_limits<double>::infinity();
  double contacts = 0;
  std::map<std::string, std::pair<double, std::int64_t>> series_sum;  // name: sum of sample means, samples
  std::map<std::string, double> series_last;
  std::map<std::string, double> settle;  // column: first time below
  std::vector<Metric> scratch;
  std::vector<std::size_t> order;

  Collector(const Spec& s, const Environment& env) : spec(s) {
    robots = env.selectArtifacts("*");
    for (std::size_t a = 0; a < env.artifactCount(); ++a) {
      const Artifact& art = env.artifact(a);
      if (const auto* sp = dynamic_cast<const SetpointInterface*>(art.driver())) {
        trackers.push_back(&art);
        setpoints.push_back(sp);
      }
      if (const auto* m = dynamic_cast<const MetricSource*>(art.driver())) sources.push_back(m);
      for (std::size_t i = 0; i < art.sensorCount(); ++i)
        if (const auto* m = dynamic_cast<const MetricSource*>(&art.sensor(i))) sources.push_back(m);
    }
    for (const auto& name : env.extensionNames())
      if (const auto* m = dynamic_cast<const MetricSource*>(env.extension(name))) sources.push_back(m);
    track_sum.assign(trackers.size(), 0);
    track_max.assign(trackers.size(), 0);
    track_n.assign(trackers.size(), 0);
    nearest.assign(robots.size(), std::numeric_limits<double>::infinity());
  }

  void sample(double t) {
    // tracking: distance of each set-point driver's vehicle to the reference it tracks now
    double track_mean = 0;
    for (std::size_t i = 0; i < trackers.size(); ++i) {
      const double e = (trackers[i]->pose().position - setpoints[i]->currentSetpoint().position).norm();
      track_sum[i] += e;
      track_max[i] = std::max(track_max[i], e);
      ++track_n[i];
      track_mean += e;
    }
    std::map<std::string, double> now;
    if (!trackers.empty()) now["tracking_error"] = track_mean / static_cast<double>(trackers.size());
    // nearest neighbours: sorted along x, each robot scans outwards until x alone is too far
    const std::size_t n = robots.size();
    order.resize(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::vector<Vec3> p(n);
    for (std::size_t i = 0; i < n; ++i) p[i] = robots[i]->pose().position;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p[a].x() < p[b].x(); });
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = order[k];
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t j = k + 1; j < n && p[order[j]].x() - p[i].x() < best; ++j)
        best = std::min(best, (p[order[j]] - p[i]).norm());
      for (std::size_t j = k; j-- > 0 && p[i].x() - p[order[j]].x() < best;)
        best = std::min(best, (p[order[j]] - p[i]).norm());
      nearest[i] = std::min(nearest[i], best);
      min_distance = std::min(min_distance, best);
    }
    // the plugins' metrics: the mean over the instances that have a value now
    std::map<std::string, std::pair<double, std::int64_t>> sums;
    for (const auto* s : sources) {
      scratch.clear();
      s->metrics(scratch);
      for (const auto& m : scratch)
        if (std::isfinite(m.value)) {
          auto& [sum, count] = sums[m.name];
          sum += m.value;
          ++count;
        }
    }
    for (const auto& [name, sc] : sums) now[name] = sc.first / static_cast<double>(sc.second);
    for (const auto& [name, v] : now) {
      auto& [sum, count] = series_sum[name];
      sum += v;
      ++count;
      series_last[name] = v;
    }
    for (const auto& m : spec.metrics)
      if (m.kind == "settle_time" && settle.count(m.column) == 0)
        if (const auto it = now.find(m.of); it != now.end() && it->second < m.below) settle[m.column] = t;
  }
};

}  // namespace

std::string Result::text() const {
  std::string s = "result " + std::to_string(run) + " " + (ok ? "1" : "0") + " " + number(load_ms) + " " +
                  number(start_ms) + " " + number(run_ms) + "\n" + row + "\n";
  for (const auto& r : robots) s += r + "\n";
  return s;
}

Result Result::parse(const std::string& text) {
  Result r;
  std::istringstream in(text);
  std::string word, line;
  int ok = 0;
  in >> word >> r.run >> ok >> r.load_ms >> r.start_ms >> r.run_ms;
  r.ok = ok != 0;
  std::getline(in, line);
  std::getline(in, r.row);
  while (std::getline(in, line))
    if (!line.empty()) r.robots.push_back(line);
  return r;
}

namespace {

std::string rowPrefix(const Spec& spec, std::int64_t run) {
  std::string row = std::to_string(run) + "," + std::to_string(spec.pointOf(run)) + "," +
                    std::to_string(spec.seedOf(run));
  for (const auto& v : spec.points[spec.pointOf(run)]) row += "," + csvField(v);
  return row;
}

Result failedRow(const Spec& spec, std::int64_t run, const std::string& status, const std::string& message) {
  Result r;
  r.run = run;
  r.row = rowPrefix(spec, run) + "," + status + std::string(spec.metricColumns().size(), ',') + "," +
          csvField(oneLine(message));
  return r;
}

}  // namespace

Result crashed(const Spec& spec, std::int64_t run, const std::string& why) { return failedRow(spec, run, "crashed", why); }

Result execute(const Spec& spec, std::int64_t run) {
  Result r;
  r.run = run;
  try {
    auto t0 = Clock::now();
    SceneOptions options = sceneOptions(spec, spec.pointOf(run));
    options.seed = spec.seedOf(run);
    Scene scene = loadScene(spec.scene, options);
    Environment& env = *scene.environment;
    env.setLogSink([](LogLevel, std::string_view) {});
    r.load_ms = msSince(t0);
    t0 = Clock::now();
    env.start();
    r.start_ms = msSince(t0);
    t0 = Clock::now();
    const Nanoseconds duration = spec.duration ? toNanoseconds(*spec.duration) : scene.duration.value_or(0);
    const std::int64_t steps = (duration + env.timestep() - 1) / env.timestep();
    const auto every = std::max<std::int64_t>(1, std::llround(1.0 / (spec.sample_hz * toSeconds(env.timestep()))));
    Collector c(spec, env);
    for (std::int64_t k = 1; k <= steps; ++k) {
      env.step();
      c.contacts += static_cast<double>(env.physics().contactCount());
      if (k % every == 0 || k == steps) c.sample(toSeconds(env.time()));
    }
    std::string row = rowPrefix(spec, run) + ",ok";
    for (const auto& m : spec.metrics) {
      if (m.kind == "tracking_error") {
        double sum = 0, max = 0;
        std::int64_t n = 0;
        for (std::size_t i = 0; i < c.trackers.size(); ++i) {
          sum += c.track_sum[i];
          n += c.track_n[i];
          max = std::max(max, c.track_max[i]);
        }
        row += "," + (n > 0 ? number(sum / static_cast<double>(n)) : std::string()) + "," +
               (n > 0 ? number(max) : std::string());
      } else if (m.kind == "min_distance") {
        row += "," + number(c.min_distance);
      } else if (m.kind == "contacts") {
        row += "," + number(c.contacts);
      } else if (m.kind == "state_hash") {
        char h[17];
        std::snprintf(h, sizeof h, "%016" PRIx64, env.stateHash());
        row += std::string(",") + h;
      } else if (m.kind == "settle_time") {
        const auto it = c.settle.find(m.column);
        row += "," + (it != c.settle.end() ? number(it->second) : std::string());
      } else {
        const auto s = c.series_sum.find(m.kind);
        const bool have = s != c.series_sum.end() && s->second.second > 0;
        row += "," + (have ? number(c.series_last[m.kind]) : std::string()) + "," +
               (have ? number(s->second.first / static_cast<double>(s->second.second)) : std::string());
      }
    }
    r.row = row + ",";
    for (std::size_t i = 0; i < c.robots.size(); ++i) {
      std::string line = std::to_string(run) + "," + csvField(c.robots[i]->name());
      const auto t = std::find(c.trackers.begin(), c.trackers.end(), c.robots[i]);
      if (t != c.trackers.end()) {
        const auto k = static_cast<std::size_t>(t - c.trackers.begin());
        line += "," + number(c.track_n[k] > 0 ? c.track_sum[k] / static_cast<double>(c.track_n[k]) : NAN) + "," +
                number(c.track_n[k] > 0 ? c.track_max[k] : NAN);
      } else {
        line += ",,";
      }
      r.robots.push_back(line + "," + number(c.nearest[i]));
    }
    env.stop();
    r.run_ms = msSince(t0);
    r.ok = true;
  } catch (const StepError& e) {
    return failedRow(spec, run, "failed", e.what());
  } catch (const std::exception& e) {
    return failedRow(spec, run, "failed", e.what());
  }
  return r;
}

}  // namespace ssx::sweep
