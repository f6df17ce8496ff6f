// The sweep file: read and checked, every problem collected, and its points (see sweep.hpp).
#include "sweep.hpp"

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <utility>

namespace ssx::sweep {

namespace {


constexpr std::int64_t kMaxRuns = 10'000'000;


// (a basis of its own since the first sweeps: the fingerprints of files already written stay)
constexpr std::uint64_t kFingerprintBasis = 1469598103934665603ull;

// Reading the sweep file: libssx's XML reader (elements and attributes with their lines), every
// problem collected.
class Reader {
 public:
  static SourceLocation at(const Descriptor& n) { return n.where(); }
  void error(const SourceLocation& where, std::string message) {
    diagnostics.push_back({Diagnostic::Severity::Error, where, std::move(message)});
  }
  // only these attributes, else an error per unknown one
  void allow(const Descriptor& n, std::initializer_list<const char*> keys) {
    for (const auto& a : n.attributes()) {
      bool known = false;
      for (const char* k : keys) known = known || a.key == k;
      if (!known) {
        std::string list;
        for (const char* k : keys) list += std::string(list.empty() ? "" : ", ") + k;
        error(at(n), "<" + n.name() + ">: unknown attribute '" + a.key + "' (it takes: " +
                         (list.empty() ? std::string("none") : list) + ")");
      }
    }
  }
  static std::string text(const Descriptor& n, const char* key, const std::string& fallback = {}) {
    const auto* a = n.find(key);
    return a != nullptr ? a->value : fallback;
  }
  std::optional<double> real(const Descriptor& n, const char* key) {
    const auto* a = n.find(key);
    if (a == nullptr) return std::nullopt;
    const std::string& v = a->value;
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(d)) {
      error(at(n), "<" + n.name() + ">: attribute '" + key + "' must be a finite number, got '" + v + "'");
      return std::nullopt;
    }
    return d;
  }
  std::optional<std::int64_t> integer(const Descriptor& n, const char* key, std::int64_t min, std::int64_t max) {
    const auto* a = n.find(key);
    if (a == nullptr) return std::nullopt;
    const std::string& v = a->value;
    char* end = nullptr;
    errno = 0;
    const long long i = std::strtoll(v.c_str(), &end, 10);
    if (v.empty() || end != v.c_str() + v.size() || errno != 0 || i < min || i > max) {
      error(at(n), "<" + n.name() + ">: attribute '" + key + "' must be a whole number in [" + std::to_string(min) +
                       ", " + std::to_string(max) + "], got '" + v + "'");
      return std::nullopt;
    }
    return i;
  }
  std::optional<bool> boolean(const Descriptor& n, const char* key) {
    const auto* a = n.find(key);
    if (a == nullptr) return std::nullopt;
    const std::string& v = a->value;
    if (v == "true" || v == "1") return true;
    if (v == "false" || v == "0") return false;
    error(at(n), "<" + n.name() + ">: attribute '" + key + "' must be true or false, got '" + v + "'");
    return std::nullopt;
  }

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

}  // namespace

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

Spec readSpec(const fs::path& file, const std::vector<fs::path>& plugin_path, std::uintmax_t max_input_bytes) {
  std::string text;
  Descriptor root;
  try {
    text = readInputFile(file, max_input_bytes);
    root = parseXml(text, file.string());
  } catch (const ConfigError& e) {
    throw SceneError({{Diagnostic::Severity::Error, e.where(), e.detail()}});
  }
  Reader r;
  Spec spec;
  spec.file = file;
  spec.plugin_path = plugin_path;
  spec.max_input_bytes = max_input_bytes;
  if (root.name() != "sweep") {
    r.error(r.at(root), "the root element of a sweep file must be <sweep>, got <" + root.name() + ">");
    throw SceneError(r.diagnostics);
  }
  r.allow(root, {"scene", "seed", "seeds", "duration", "threads", "sample_hz", "extensions"});
  const SourceLocation root_at = r.at(root);
  spec.where = root_at;
  std::string scene_text;
  if (Reader::text(root, "scene").empty()) {
    r.error(root_at, "<sweep>: missing attribute 'scene' (the scene file to vary, relative to this file)");
  } else {
    spec.scene = fs::path(Reader::text(root, "scene"));
    if (spec.scene.is_relative()) spec.scene = file.parent_path() / spec.scene;
    try {
      scene_text = readInputFile(spec.scene, max_input_bytes);
    } catch (const ConfigError& e) {
      r.error(root_at, "<sweep>: scene '" + spec.scene.string() + "': " + e.detail());
    }
  }
  if (const auto* given = root.find("seed")) {
    if (const auto seed = parseSeed(given->value))
      spec.seed = *seed;
    else
      r.error(given->where, "<sweep>: attribute 'seed' must be a whole number from 0 to " + std::to_string(kMaxSeed) +
                                ", got '" + given->value + "'");
  }
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
  if (const auto* a = root.find("extensions")) {
    const std::string& v = a->value;
    if (v == "keep") spec.extensions = true;
    else if (v != "drop") r.error(root_at, "<sweep>: attribute 'extensions' must be drop or keep, got '" + v + "'");
  }

  // the varied parameters: at most one of <grid>, <list>, <random>
  std::string mode;
  std::int64_t draws = 0;
  const Descriptor* vary = nullptr;
  bool have_metrics = false;
  for (const Descriptor& c : root.children()) {
    const std::string& n = c.name();
    if (n == "grid" || n == "list" || n == "random") {
      if (vary) {
        r.error(r.at(c), "<" + n + ">: a sweep varies its parameters one way: <" + mode + "> is already at line " +
                             std::to_string(r.at(*vary).line));
        continue;
      }
      vary = &c;
      mode = n;
      if (n == "random") {
        r.allow(c, {"draws"});
        draws = r.integer(c, "draws", 1, 1'000'000).value_or(0);
        if (!c.has("draws")) r.error(r.at(c), "<random>: missing attribute 'draws' (how many points to draw)");
      } else {
        r.allow(c, {});
      }
      for (const Descriptor& p : c.children()) {
        const SourceLocation where = r.at(p);
        if (p.name() != "parameter") {
          r.error(where, "<" + p.name() + ">: unknown element in <" + n + "> (it holds <parameter>s)");
          continue;
        }
        Parameter param;
        param.where = where;
        param.name = Reader::text(p, "name");
        param.target = Reader::text(p, "target");
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
          param.values = splitValues(Reader::text(p, "values"));
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
      for (const Descriptor& m : c.children()) {
        MetricSpec ms;
        ms.kind = m.name();
        ms.where = r.at(m);
        if (ms.kind == "tracking_error" || ms.kind == "min_distance" || ms.kind == "contacts" ||
            ms.kind == "state_hash") {
          r.allow(m, {});
        } else if (ms.kind == "settle_time") {
          r.allow(m, {"of", "below", "column"});
          ms.of = Reader::text(m, "of");
          ms.column = Reader::text(m, "column", "settle_time");
          const auto below = r.real(m, "below");
          if (ms.of.empty() || !below)
            r.error(ms.where, "<settle_time>: needs 'of' (tracking_error or a plugin metric) and 'below' (the threshold)");
          else
            ms.below = *below;
          if (!plainName(ms.column)) r.error(ms.where, "<settle_time>: 'column' must be letters, digits and '_'");
        } else if (ms.kind == "plugin") {
          r.allow(m, {"name"});
          ms.kind = Reader::text(m, "name");
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
    // every column once: a metric's column may be neither a column of every row nor a parameter's
    std::set<std::string> seen(kFixedColumns.begin(), kFixedColumns.end());
    for (const auto& p : spec.parameters) seen.insert(p.name);
    for (const auto& m : spec.metrics) {
      Spec one;
      one.metrics = {m};
      for (const auto& c : one.metricColumns())
        if (!seen.insert(c).second)
          r.error(m.where, "<metrics>: column '" + c + "' would appear twice in the results (" +
                               (kFixedColumns.count(c) != 0 ? "every row has it" : "another column has this name") +
                               "): choose another name");
    }
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
        r.error(r.at(*vary), "<grid>: " + number(count) + " points x " + std::to_string(spec.seeds) +
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
  std::snprintf(fp, sizeof fp, "%016" PRIx64, fnv1a(scene_text, fnv1a(text, kFingerprintBasis)));
  spec.fingerprint = fp;
  return spec;
}

}  // namespace ssx::sweep
