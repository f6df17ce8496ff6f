// The sweep file, its checks before any run, and one run with its metrics (see sweep.hpp).
#include "sweep.hpp"

#include <pugixml.hpp>

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

constexpr std::int64_t kMaxRuns = 10'000'000;

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// (a basis of its own since the first sweeps: the fingerprints of files already written stay)
constexpr std::uint64_t kFingerprintBasis = 1469598103934665603ull;

// Reading the sweep file: pugixml, with line numbers from offsets, every problem collected.
class Reader {
 public:
  Reader(fs::path file, std::string text) : file_(std::move(file)), text_(std::move(text)) {}

  SourceLocation at(const pugi::xml_node& n) const {
    const auto offset = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, n.offset_debug()));
    return {file_.string(), 1 + static_cast<int>(std::count(text_.begin(), text_.begin() + static_cast<std::ptrdiff_t>(
                                                                                std::min(offset, text_.size())),
                                                            '\n'))};
  }
  void error(const SourceLocation& where, std::string message) {
    diagnostics.push_back({Diagnostic::Severity::Error, where, std::move(message)});
  }
  // only these attributes, else an error per unknown one
  void allow(const pugi::xml_node& n, std::initializer_list<const char*> keys) {
    for (const auto& a : n.attributes()) {
      bool known = false;
      for (const char* k : keys) known = known || std::string(a.name()) == k;
      if (!known) {
        std::string list;
        for (const char* k : keys) list += std::string(list.empty() ? "" : ", ") + k;
        error(at(n), "<" + std::string(n.name()) + ">: unknown attribute '" + a.name() + "' (it takes: " +
                         (list.empty() ? std::string("none") : list) + ")");
      }
    }
  }
  std::optional<double> real(const pugi::xml_node& n, const char* key) {
    const auto a = n.attribute(key);
    if (!a) return std::nullopt;
    const std::string v = a.value();
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(d)) {
      error(at(n), "<" + std::string(n.name()) + ">: attribute '" + key + "' must be a finite number, got '" + v + "'");
      return std::nullopt;
    }
    return d;
  }
  std::optional<std::int64_t> integer(const pugi::xml_node& n, const char* key, std::int64_t min, std::int64_t max) {
    const auto a = n.attribute(key);
    if (!a) return std::nullopt;
    const std::string v = a.value();
    char* end = nullptr;
    errno = 0;
    const long long i = std::strtoll(v.c_str(), &end, 10);
    if (v.empty() || end != v.c_str() + v.size() || errno != 0 || i < min || i > max) {
      error(at(n), "<" + std::string(n.name()) + ">: attribute '" + key + "' must be a whole number in [" +
                       std::to_string(min) + ", " + std::to_string(max) + "], got '" + v + "'");
      return std::nullopt;
    }
    return i;
  }
  std::optional<bool> boolean(const pugi::xml_node& n, const char* key) {
    const auto a = n.attribute(key);
    if (!a) return std::nullopt;
    const std::string v = a.value();
    if (v == "true" || v == "1") return true;
    if (v == "false" || v == "0") return false;
    error(at(n), "<" + std::string(n.name()) + ">: attribute '" + key + "' must be true or false, got '" + v + "'");
    return std::nullopt;
  }

  fs::path file_;
  std::string text_;
  std::vector<Diagnostic> diagnostics;
};

bool plainName(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// values: separated by ';' when there is one (vectors: "0 0 1; 0 0 2"), else by white space
std::vector<std::string> splitValues(const std::string& text) {
  std::vector<std::string> out;
  auto trim = [](std::string s) {
    const auto b = s.find_first_not_of(" \t\r\n");
    const auto e = s.find_last_not_of(" \t\r\n");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  };
  if (text.find(';') != std::string::npos) {
    std::stringstream in(text);
    std::string part;
    while (std::getline(in, part, ';')) out.push_back(trim(part));
  } else {
    std::stringstream in(text);
    std::string part;
    while (in >> part) out.push_back(part);
  }
  return out;
}

const std::set<std::string> kFixedColumns{"run", "point", "seed", "status", "message"};

SceneOptions sceneOptions(const Spec& spec, std::size_t point) {
  SceneOptions o;
  o.plugin_path = spec.plugin_path;
  o.threads = spec.threads;
  o.render_engine = "null";
  o.extensions = spec.extensions;
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

std::vector<std::string> Spec::metricColumns() const {
  std::vector<std::string> c;
  for (const auto& m : metrics) {
    if (m.kind == "tracking_error") {
      c.insert(c.end(), {"tracking_error_mean", "tracking_error_max"});
    } else if (m.kind == "min_distance" || m.kind == "contacts" || m.kind == "state_hash") {
      c.push_back(m.kind);
    } else if (m.kind == "settle_time") {
      c.push_back(m.column);
    } else {  // a plugin's
      c.insert(c.end(), {m.kind + "_final", m.kind + "_mean"});
    }
  }
  return c;
}

std::vector<std::string> Spec::columns() const {
  std::vector<std::string> c{"run", "point", "seed"};
  for (const auto& p : parameters) c.push_back(p.name);
  c.push_back("status");
  const auto m = metricColumns();
  c.insert(c.end(), m.begin(), m.end());
  c.push_back("message");
  return c;
}

Spec readSpec(const fs::path& file, const std::vector<fs::path>& plugin_path) {
  const std::string text = readText(file);
  Reader r(file, text);
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_buffer(text.data(), text.size(), pugi::parse_default);
  if (text.empty() && !fs::is_regular_file(file))
    throw SceneError({{Diagnostic::Severity::Error, {file.string(), 0}, "cannot read the sweep file (missing, a directory, or no permission)"}});
  if (!parsed) {
    const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + std::min<std::ptrdiff_t>(parsed.offset, static_cast<std::ptrdiff_t>(text.size())), '\n'));
    throw SceneError({{Diagnostic::Severity::Error, {file.string(), line}, std::string("XML syntax: ") + parsed.description()}});
  }
  const pugi::xml_node root = doc.document_element();
  Spec spec;
  spec.file = file;
  spec.plugin_path = plugin_path;
  if (std::string(root.name()) != "sweep") {
    r.error(r.at(root), "the root element of a sweep file must be <sweep>, got <" + std::string(root.name()) + ">");
    throw SceneError(r.diagnostics);
  }
  r.allow(root, {"scene", "seed", "seeds", "duration", "threads", "sample_hz", "extensions"});
  const SourceLocation root_at = r.at(root);
  spec.where = root_at;
  if (!root.attribute("scene") || std::string(root.attribute("scene").value()).empty()) {
    r.error(root_at, "<sweep>: missing attribute 'scene' (the scene file to vary, relative to this file)");
  } else {
    spec.scene = fs::path(root.attribute("scene").value());
    if (spec.scene.is_relative()) spec.scene = file.parent_path() / spec.scene;
    if (!fs::is_regular_file(spec.scene))
      r.error(root_at, "<sweep>: cannot read scene '" + spec.scene.string() + "' (missing, a directory, or no permission)");
  }
  spec.seed = static_cast<std::uint64_t>(r.integer(root, "seed", 0, std::numeric_limits<std::int64_t>::max()).value_or(0));
  spec.seeds = r.integer(root, "seeds", 1, 1'000'000).value_or(1);
  spec.threads = static_cast<int>(r.integer(root, "threads", 0, 1024).value_or(1));
  if (const auto d = r.real(root, "duration")) {
    if (*d <= 0 || *d > kMaxDurationSeconds)
      r.error(root_at, "<sweep>: attribute 'duration' must be in (0, 1e9] s, got " + number(*d));
    else
      spec.duration = *d;
  }
  if (const auto h = r.real(root, "sample_hz")) {
    if (*h <= 0) r.error(root_at, "<sweep>: attribute 'sample_hz' must be positive, got " + number(*h));
    else spec.sample_hz = *h;
  }
  if (const auto a = root.attribute("extensions")) {
    const std::string v = a.value();
    if (v == "keep") spec.extensions = true;
    else if (v != "drop") r.error(root_at, "<sweep>: attribute 'extensions' must be drop or keep, got '" + v + "'");
  }

  // the varied parameters: at most one of <grid>, <list>, <random>
  std::string mode;
  std::int64_t draws = 0;
  pugi::xml_node vary;
  bool have_metrics = false;
  for (const pugi::xml_node& c : root.children()) {
    if (c.type() != pugi::node_element) continue;
    const std::string n = c.name();
    if (n == "grid" || n == "list" || n == "random") {
      if (vary) {
        r.error(r.at(c), "<" + n + ">: a sweep varies its parameters one way: <" + mode + "> is already at line " +
                             std::to_string(r.at(vary).line));
        continue;
      }
      vary = c;
      mode = n;
      if (n == "random") {
        r.allow(c, {"draws"});
        draws = r.integer(c, "draws", 1, 1'000'000).value_or(0);
        if (!c.attribute("draws")) r.error(r.at(c), "<random>: missing attribute 'draws' (how many points to draw)");
      } else {
        r.allow(c, {});
      }
      for (const pugi::xml_node& p : c.children()) {
        if (p.type() != pugi::node_element) continue;
        const SourceLocation where = r.at(p);
        if (std::string(p.name()) != "parameter") {
          r.error(where, "<" + std::string(p.name()) + ">: unknown element in <" + n + "> (it holds <parameter>s)");
          continue;
        }
        Parameter param;
        param.where = where;
        param.name = p.attribute("name").value();
        param.target = p.attribute("target").value();
        if (mode == "random") {
          r.allow(p, {"name", "target", "min", "max", "integer", "log"});
          const auto lo = r.real(p, "min");
          const auto hi = r.real(p, "max");
          param.integer = r.boolean(p, "integer").value_or(false);
          param.log = r.boolean(p, "log").value_or(false);
          if (!lo || !hi) {
            r.error(where, "<parameter>: a random parameter needs 'min' and 'max'");
          } else if (!(*lo < *hi) || (param.log && *lo <= 0)) {
            r.error(where, "<parameter>: needs min < max" + std::string(param.log ? " and min > 0 (log)" : "") +
                               ", got " + number(*lo) + " and " + number(*hi));
          } else {
            param.min = *lo;
            param.max = *hi;
          }
        } else {
          r.allow(p, {"name", "target", "values"});
          param.values = splitValues(p.attribute("values").value());
          if (param.values.empty()) r.error(where, "<parameter>: missing or empty attribute 'values'");
        }
        if (!plainName(param.name))
          r.error(where, "<parameter>: attribute 'name' (its column) must be letters, digits and '_', got '" +
                             param.name + "'");
        else if (kFixedColumns.count(param.name) != 0)
          r.error(where, "<parameter>: name '" + param.name + "' is a column of every row; choose another");
        for (const auto& other : spec.parameters)
          if (other.name == param.name)
            r.error(where, "<parameter>: name '" + param.name + "' given twice (first at line " +
                               std::to_string(other.where.line) + ")");
        if (param.target.empty()) r.error(where, "<parameter>: missing attribute 'target' (e.g. swarm/driver@formation_gain)");
        spec.parameters.push_back(std::move(param));
      }
      if (spec.parameters.empty()) r.error(r.at(c), "<" + n + ">: no <parameter> in it");
    } else if (n == "metrics") {
      have_metrics = true;
      r.allow(c, {});
      for (const pugi::xml_node& m : c.children()) {
        if (m.type() != pugi::node_element) continue;
        MetricSpec ms;
        ms.kind = m.name();
        ms.where = r.at(m);
        if (ms.kind == "tracking_error" || ms.kind == "min_distance" || ms.kind == "contacts" ||
            ms.kind == "state_hash") {
          r.allow(m, {});
        } else if (ms.kind == "settle_time") {
          r.allow(m, {"of", "below", "column"});
          ms.of = m.attribute("of").value();
          ms.column = m.attribute("column") ? m.attribute("column").value() : "settle_time";
          const auto below = r.real(m, "below");
          if (ms.of.empty() || !below)
            r.error(ms.where, "<settle_time>: needs 'of' (tracking_error or a plugin metric) and 'below' (the threshold)");
          else
            ms.below = *below;
          if (!plainName(ms.column)) r.error(ms.where, "<settle_time>: 'column' must be letters, digits and '_'");
        } else if (ms.kind == "plugin") {
          r.allow(m, {"name"});
          ms.kind = m.attribute("name").value();
          if (!plainName(ms.kind)) r.error(ms.where, "<plugin>: attribute 'name' must name a metric a plugin publishes");
        } else {
          r.error(ms.where, "<" + ms.kind + ">: unknown metric (built in: tracking_error, min_distance, contacts, "
                                            "state_hash, settle_time; a plugin's: <plugin name=\"...\"/>)");
          continue;
        }
        spec.metrics.push_back(std::move(ms));
      }
    } else {
      r.error(r.at(c), "<" + n + ">: unknown element in <sweep> (it holds <grid>, <list> or <random>, and <metrics>)");
    }
  }
  if (!have_metrics)
    for (const char* k : {"tracking_error", "min_distance", "contacts", "state_hash"})
      spec.metrics.push_back({k, "", 0, "", root_at});
  {
    std::set<std::string> seen;
    for (const auto& p : spec.parameters) seen.insert(p.name);
    for (const auto& c : spec.metricColumns())
      if (!seen.insert(c).second) r.error(root_at, "<sweep>: column '" + c + "' would appear twice");
  }

  // the points
  if (r.diagnostics.empty()) {
    const std::size_t np = spec.parameters.size();
    if (mode.empty()) {
      spec.points.emplace_back();
    } else if (mode == "list") {
      for (const auto& p : spec.parameters)
        if (p.values.size() != spec.parameters.front().values.size())
          r.error(p.where, "<parameter>: a <list> pairs the k-th values of every parameter: '" + p.name + "' has " +
                               std::to_string(p.values.size()) + " values, '" + spec.parameters.front().name + "' " +
                               std::to_string(spec.parameters.front().values.size()));
      if (r.diagnostics.empty())
        for (std::size_t k = 0; k < spec.parameters.front().values.size(); ++k) {
          std::vector<std::string> point;
          for (const auto& p : spec.parameters) point.push_back(p.values[k]);
          spec.points.push_back(std::move(point));
        }
    } else if (mode == "grid") {
      double count = 1;
      for (const auto& p : spec.parameters) count *= static_cast<double>(p.values.size());
      if (count * static_cast<double>(spec.seeds) > kMaxRuns) {
        r.error(r.at(vary), "<grid>: " + number(count) + " points x " + std::to_string(spec.seeds) +
                                " seeds is more than 10,000,000 runs");
      } else {
        std::vector<std::size_t> index(np, 0);
        for (;;) {
          std::vector<std::string> point;
          for (std::size_t i = 0; i < np; ++i) point.push_back(spec.parameters[i].values[index[i]]);
          spec.points.push_back(std::move(point));
          std::size_t i = np;  // the last parameter varies fastest
          while (i > 0 && ++index[i - 1] == spec.parameters[i - 1].values.size()) index[--i] = 0;
          if (i == 0) break;
        }
      }
    } else {  // random: drawn from the sweep seed, the same in every process
      Random rng(deriveSeed(spec.seed, 0x504f494e54));
      for (std::int64_t k = 0; k < draws; ++k) {
        std::vector<std::string> point;
        for (const auto& p : spec.parameters) {
          const double u = rng.uniform();
          double v = p.log ? std::exp(std::log(p.min) + u * (std::log(p.max) - std::log(p.min))) : p.min + u * (p.max - p.min);
          if (p.integer) v = std::clamp(std::floor(v + 0.5), std::ceil(p.min), std::floor(p.max));
          point.push_back(p.integer ? std::to_string(static_cast<std::int64_t>(v)) : number(v));
        }
        spec.points.push_back(std::move(point));
      }
    }
    if (spec.runCount() > kMaxRuns) r.error(root_at, "<sweep>: more than 10,000,000 runs");
  }
  if (!r.diagnostics.empty()) throw SceneError(r.diagnostics);
  char fp[17];
  std::snprintf(fp, sizeof fp, "%016" PRIx64, fnv1a(readText(spec.scene), fnv1a(text, kFingerprintBasis)));
  spec.fingerprint = fp;
  return spec;
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
