#include <ssx/environment.hpp>
#include <ssx/parameters.hpp>

#include "plugin/parameter_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

namespace ssx {

std::string Diagnostic::str() const {
  return where.str() + (severity == Severity::Error ? ": error: " : ": warning: ") + message;
}

namespace {

std::string show(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", v);
  return text;
}

std::vector<std::string> words(const char* text) {
  std::istringstream in(text != nullptr ? text : "");
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

const char* typeName(std::uint32_t type) {
  switch (type) {
    case SSX_PARAM_BOOL:
      return "bool";
    case SSX_PARAM_INT:
      return "int";
    case SSX_PARAM_REAL:
      return "real";
    case SSX_PARAM_TEXT:
      return "text";
    case SSX_PARAM_VEC3:
      return "vec3";
    case SSX_PARAM_CHOICE:
      return "choice";
    default:
      return "?";
  }
}

// "> 0", ">= 0 and <= 1", or ""
std::string boundsText(const ssx_plugin_param& p) {
  std::string out;
  if ((p.flags & SSX_PARAM_HAS_MIN) != 0) out += std::string((p.flags & SSX_PARAM_MIN_OPEN) != 0 ? "> " : ">= ") + show(p.min);
  if ((p.flags & SSX_PARAM_HAS_MAX) != 0)
    out += std::string(out.empty() ? "" : " and ") + ((p.flags & SSX_PARAM_MAX_OPEN) != 0 ? "< " : "<= ") + show(p.max);
  return out;
}

bool inBounds(const ssx_plugin_param& p, double v) {
  if ((p.flags & SSX_PARAM_HAS_MIN) != 0 && ((p.flags & SSX_PARAM_MIN_OPEN) != 0 ? !(v > p.min) : !(v >= p.min)))
    return false;
  if ((p.flags & SSX_PARAM_HAS_MAX) != 0 && ((p.flags & SSX_PARAM_MAX_OPEN) != 0 ? !(v < p.max) : !(v <= p.max)))
    return false;
  return true;
}

// the period of the loop a rate sets, in runs of the plugin (a whole number when it fits)
double runsOf(double rate_hz, const PluginContext& context) {
  const double loop_ns = 1e9 / rate_hz;
  return loop_ns / static_cast<double>(context.period());
}

}  // namespace

std::int64_t runsPerPeriod(double rate_hz, const PluginContext& context) {
  if (!(rate_hz > 0) || context.period() <= 0) return 0;
  return std::llround(runsOf(rate_hz, context));
}

namespace {
// whether v is one of the space-separated words of `choices`
bool isChoice(const char* choices, std::string_view v) {
  std::string_view rest = choices != nullptr ? choices : "";
  while (!rest.empty()) {
    const std::size_t start = rest.find_first_not_of(' ');
    if (start == std::string_view::npos) break;
    rest.remove_prefix(start);
    const std::size_t end = std::min(rest.find(' '), rest.size());
    if (rest.substr(0, end) == v) return true;
    rest.remove_prefix(end);
  }
  return false;
}
}  // namespace

namespace detail {

std::vector<Diagnostic> checkParametersNamed(std::span<const ssx_plugin_param> declarations, Descriptor& params,
                                             const PluginContext& context, const std::string& what,
                                             const std::vector<std::string>* only) {
  // with `only`, the declarations and attributes of those names (a swarm member's own values)
  auto selected = [&](std::string_view key) {
    return only == nullptr || std::find(only->begin(), only->end(), key) != only->end();
  };
  std::vector<Diagnostic> out;
  auto fail = [&](const SourceLocation& where, const std::string& message) {
    out.push_back({Diagnostic::Severity::Error, where, "<" + params.name() + ">: " + what + ": " + message});
  };
  // every attribute given is declared, or a warning
  for (const auto& a : params.attributes()) {
    if (!selected(a.key)) continue;
    bool declared = false;
    for (const auto& d : declarations) declared = declared || a.key == d.name;
    if (declared) continue;
    std::string known;
    std::vector<std::string> names;
    for (const auto& d : declarations) {
      known += std::string(known.empty() ? "" : ", ") + d.name;
      names.emplace_back(d.name);
    }
    const std::string nearest = nearestName(a.key, names);
    // a near name is what the user meant, most likely: it alone (a quadrotor has 75 parameters);
    // with none near, every name it has
    out.push_back({Diagnostic::Severity::Warning, a.where,
                   "unknown parameter '" + a.key + "' of " + what + " (ignored; " +
                       (!nearest.empty() ? "did you mean '" + nearest + "'?"
                                         : "it has: " + (known.empty() ? std::string("none") : known)) +
                       ")"});
  }
  // absent parameters read as their declared defaults
  params.setDeclarations(declarations);
  for (const auto& d : declarations) {
    if (!selected(d.name)) continue;
    const Descriptor::Attribute* a = params.find(d.name);
    const bool defaulted = a == nullptr;
    Descriptor::Attribute declared_default;
    if (a == nullptr) {
      if ((d.flags & SSX_PARAM_REQUIRED) != 0) {
        fail(params.where(), "missing parameter '" + std::string(d.name) + "' (" + d.doc + ")");
        continue;
      }
      if (d.default_value == nullptr || d.default_value[0] == '\0') continue;
      // a default is checked too: a rate may not fit this plugin's period
      declared_default = {d.name, d.default_value, params.where(), true};
      a = &declared_default;
    }
    auto outOfBounds = [&](const std::string& value) {
      const std::string unit = d.unit != nullptr && d.unit[0] != '\0' ? std::string(" ") + d.unit : "";
      fail(a->where, "parameter '" + std::string(d.name) + "' must be " + boundsText(d) + unit + ", got '" + value +
                         "' (" + d.doc + ")");
    };
    try {
      switch (d.type) {
        case SSX_PARAM_BOOL:
          (void)params.parse<bool>(*a);
          break;
        case SSX_PARAM_INT: {
          const auto v = params.parse<std::int64_t>(*a);
          if (!inBounds(d, static_cast<double>(v))) outOfBounds(a->value);
          break;
        }
        case SSX_PARAM_REAL: {
          const double v = params.parse<double>(*a);  // finite: parse refuses anything else
          if (!inBounds(d, v)) {
            outOfBounds(a->value);
            break;
          }
          // a rate's period must fit the nanosecond clock
          if (d.unit != nullptr && std::string_view(d.unit) == "Hz" && v > 0 && v < kMinRateHz) {
            fail(a->where, "parameter '" + std::string(d.name) + "' must be 0 or at least 1e-6 Hz, got '" +
                               a->value + "' (" + d.doc + ")");
            break;
          }
          if ((d.flags & SSX_PARAM_RATE) != 0 && v > 0 && context.period() > 0) {
            const double runs = runsOf(v, context);
            if (runs < 1 - 1e-9 || std::abs(runs - std::round(runs)) > 1e-6 * runs) {
              const std::string set_at =
                  context.period_from.line > 0 ? ", set at " + context.period_from.str() : std::string();
              fail(a->where, "parameter '" + std::string(d.name) + "' = " + a->value + " Hz" +
                                 (defaulted ? " (its default)" : "") + ": its period (" + show(1e3 / v) +
                                 " ms) must be a whole multiple of this plugin's period (" +
                                 std::to_string(context.period_steps) + " step(s) of " +
                                 show(toSeconds(context.timestep) * 1e3) + " ms" + set_at +
                                 "); choose a rate or a plugin period that divides it");
            }
          }
          break;
        }
        case SSX_PARAM_VEC3: {
          const Vec3 v = params.parse<Vec3>(*a);
          if (!inBounds(d, v.x()) || !inBounds(d, v.y()) || !inBounds(d, v.z())) outOfBounds(a->value);
          break;
        }
        case SSX_PARAM_CHOICE: {
          const std::string& v = a->value;
          if (!isChoice(d.choices, v)) {
            const auto choices = words(d.choices);
            std::string list;
            for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
            fail(a->where, "parameter '" + std::string(d.name) + "' must be one of " + list + ", got '" + v + "'");
          }
          break;
        }
        default:
          break;  // text: anything
      }
    } catch (const ConfigError& e) {
      fail(a->where, "parameter '" + std::string(d.name) + "' must be " + typeName(d.type) +
                         (d.type == SSX_PARAM_VEC3 ? " (\"x y z\")" : "") + ", got '" + a->value + "'");
    }
  }
  return out;
}

}  // namespace detail

std::vector<Diagnostic> checkParameters(std::span<const ssx_plugin_param> declarations, Descriptor& params,
                                        const PluginContext& context, const std::string& what) {
  return detail::checkParametersNamed(declarations, params, context, what, nullptr);
}

std::string parameterTable(std::span<const ssx_plugin_param> declarations) {
  constexpr const char* kHeader = "| parameter | type | unit | default | allowed | description |\n|---|---|---|---|---|---|\n";
  std::string out;
  const char* group = nullptr;
  for (const auto& d : declarations) {
    // a class made of parts: a table per part, under its name
    const bool new_group = out.empty() || (d.group != nullptr && (group == nullptr || std::strcmp(d.group, group) != 0));
    if (new_group) {
      if (d.group != nullptr) out += (out.empty() ? "" : "\n") + std::string("**") + d.group + "**\n\n";
      out += kHeader;
      group = d.group;
    }
    std::string allowed = d.type == SSX_PARAM_CHOICE ? std::string(d.choices) : boundsText(d);
    if ((d.flags & SSX_PARAM_OUTPUT) != 0)
      allowed += std::string(allowed.empty() ? "" : "; ") + "a file it writes: not one the run reads or writes already";
    if ((d.flags & SSX_PARAM_RATE) != 0)
      allowed += std::string(allowed.empty() ? "" : "; ") + "period a whole multiple of the plugin's";
    std::string def = d.default_value != nullptr ? d.default_value : "";
    if ((d.flags & SSX_PARAM_REQUIRED) != 0) def = "(required)";
    out += "| `" + std::string(d.name) + "` | " + typeName(d.type) + " | " + (d.unit != nullptr ? d.unit : "") +
           " | " + (def.empty() ? "" : "`" + def + "`") + " | " + allowed + " | " + (d.doc != nullptr ? d.doc : "") +
           " |\n";
  }
  return out;
}

}  // namespace ssx
