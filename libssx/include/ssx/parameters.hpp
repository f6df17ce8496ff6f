#pragma once
/// @file
/// Declared plugin parameters: what a plugin class accepts (name, type, unit, default, range or
/// choices, one line of doc), as plain constant data in its manifest. The scene loader checks
/// every value against the declarations while loading, so `ssx validate` reports every bad
/// parameter and nothing runs before all checks pass; `ssx plugins --params` prints them and the
/// tables in docs/scene-format.md are made from them.
///
/// A plugin class declares its parameters as a static member:
///
///     static constexpr ssx_plugin_param kParameters[] = {
///         ssx::param::real("range", "2.5", "m", ssx::param::positive(), "how far it sees"),
///         ssx::param::choice("frame", "world", "world body", "frame of the relative positions"),
///     };
///
/// and may add a static check of what one parameter alone cannot say (names of nodes, one value
/// below another, a sensor it needs), which runs while loading too:
///
///     static void validate(const ssx::Descriptor& params, const ssx::PluginContext& context);
///
/// `configure` then reads the values with `params.get<T>(name)`: every declared parameter with a
/// default is present by then, already checked.

#include <ssx/descriptor.hpp>
#include <ssx/export.hpp>
#include <ssx/shared_value.hpp>
#include <ssx/types.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <typeindex>
#include <typeinfo>
#include <utility>
#include <vector>

extern "C" {

/// The type of a declared parameter.
enum ssx_param_type : std::uint32_t {
  SSX_PARAM_BOOL = 1,    ///< true/false/1/0
  SSX_PARAM_INT = 2,     ///< a whole number (64 bits)
  SSX_PARAM_REAL = 3,    ///< a finite number
  SSX_PARAM_TEXT = 4,    ///< any text (names, lists of names)
  SSX_PARAM_VEC3 = 5,    ///< "x y z", each finite; bounds apply to each component
  SSX_PARAM_CHOICE = 6,  ///< one of the words in `choices` (separated by spaces)
};

/// Flags of a declared parameter.
enum ssx_param_flag : std::uint32_t {
  SSX_PARAM_REQUIRED = 1u,  ///< must be given
  SSX_PARAM_HAS_MIN = 2u,   ///< value >= min (> min with MIN_OPEN)
  SSX_PARAM_MIN_OPEN = 4u,  ///< with HAS_MIN: the minimum itself is excluded
  SSX_PARAM_HAS_MAX = 8u,  ///< value <= max (< max with MAX_OPEN)
  SSX_PARAM_MAX_OPEN = 16u,  ///< with HAS_MAX: the maximum itself is excluded
  /// a rate in Hz of a loop inside the plugin: unless 0, its period must be a whole multiple of
  /// the plugin's own period (the plugin runs its loop every k of its runs)
  SSX_PARAM_RATE = 32u,
  /// a file the plugin writes (a text parameter, relative to the working directory): the loader
  /// checks it with the run's other files before anything runs (ssx/run_files.hpp): not a file the
  /// run reads, not another output, a regular or a new file
  SSX_PARAM_OUTPUT = 64u,
};

/// One declared parameter. `default_value` is text in the parameter's own syntax, or "" when the
/// default is computed (say so in `doc`); `unit` is "" when there is none.
struct ssx_plugin_param {
  const char* name;           ///< the attribute's name in a scene
  std::uint32_t type;         ///< an ssx_param_type
  std::uint32_t flags;        ///< ssx_param_flag values, or'ed
  const char* unit;           ///< "m", "rad/s", ...; "" when none
  const char* default_value;  ///< text in the parameter's syntax; "" when computed or required
  double min;                 ///< lower bound (with SSX_PARAM_HAS_MIN)
  double max;                 ///< upper bound (with SSX_PARAM_HAS_MAX)
  const char* choices;        ///< SSX_PARAM_CHOICE: the accepted words, separated by spaces
  const char* doc;            ///< one line on what it does
  /// the part of the class it belongs to ("vehicle", "controller"), or null: the tables of a class
  /// made of parts are printed part by part (ssx::param::join)
  const char* group;
};

}  // extern "C"

namespace ssx {

class Artifact;
class Environment;

/// A message about a scene or a parameter, with where it came from.
struct SSX_EXPORT Diagnostic {
  /// A warning lets the run go on; an error stops it before it starts.
  enum class Severity : std::uint8_t { Warning, Error };
  Severity severity = Severity::Error;  ///< warning or error
  SourceLocation where;                 ///< file and line (empty when not from a file)
  std::string message;                  ///< what is wrong and what to do, without the location
  /// "file:line: error: message" (or warning).
  std::string str() const;
};

/// What a plugin's static `validate` may look at, while the scene is loaded (nothing has run).
struct PluginContext {
  const Environment* environment = nullptr;  ///< being populated: every artifact so far, nodes and plugins
  const Artifact* artifact = nullptr;        ///< the plugin's artifact (null for an extension)
  std::int64_t period_steps = 1;             ///< the plugin's period, in steps
  Nanoseconds timestep = 0;                  ///< the environment's timestep
  SourceLocation period_from;                ///< where the period was set, if in a file
  /// What the scene loader keeps for `shared` while it loads: one table per plugin class.
  using SharedValues = std::map<std::pair<std::type_index, std::string>, std::shared_ptr<const void>>;
  SharedValues* shared_values = nullptr;  ///< this plugin class's table, or null (then nothing is shared)
  /// The plugin's period in nanoseconds.
  Nanoseconds period() const { return period_steps * timestep; }
  /// What `validate` works out alike for many instances of a class, worked out once while the
  /// scene loads (as PluginSetup::shared while the environment starts): `make()`'s result (a T,
  /// or a pointer to one) for the first instance that asks for a T under `key`, the same object
  /// for every later one. `key` must hold everything the value is computed from. A `make` that
  /// throws leaves nothing behind (the next instance tries again).
  template <class T, class Make>
  std::shared_ptr<const T> shared(std::string_view key, Make&& make) const {
    return detail::sharedValue<T>(
        shared_values != nullptr ? &(*shared_values)[{std::type_index(typeid(T)), std::string(key)}] : nullptr,
        std::forward<Make>(make));
  }
};

/// Checks `params` against `declarations`: types, ranges, choices, required parameters, rates
/// against the plugin's period (`context`). Attaches the declarations to `params`, so that absent
/// parameters read as their declared defaults (Descriptor::get). Undeclared parameters are
/// warnings (left unread: mark them read to silence the environment's own warning about
/// parameters no plugin read).
/// `what` names the plugin in messages ("driver 'quadrotor'"). Returns every problem found.
SSX_EXPORT std::vector<Diagnostic> checkParameters(std::span<const ssx_plugin_param> declarations,
                                                   Descriptor& params, const PluginContext& context,
                                                   const std::string& what);

/// The period, in runs of the plugin, of a rate parameter (SSX_PARAM_RATE) that checkParameters
/// accepted: how many of the plugin's runs make one period of the rate. 0 for a rate of 0.
SSX_EXPORT std::int64_t runsPerPeriod(double rate_hz, const PluginContext& context);

/// Builders for declarations, usable in constant expressions.
namespace param {

/// Bounds of a number (each component of a vector).
struct Bounds {
  std::uint32_t flags = 0;  ///< SSX_PARAM_HAS_MIN, _MIN_OPEN, _HAS_MAX, _MAX_OPEN
  double min = 0;           ///< lower bound, when HAS_MIN
  double max = 0;           ///< upper bound, when HAS_MAX
};
/// No bounds.
constexpr Bounds any() { return {}; }
/// value >= v
constexpr Bounds atLeast(double v) { return {SSX_PARAM_HAS_MIN, v, 0}; }
/// value > v
constexpr Bounds above(double v) { return {SSX_PARAM_HAS_MIN | SSX_PARAM_MIN_OPEN, v, 0}; }
/// value <= v
constexpr Bounds atMost(double v) { return {SSX_PARAM_HAS_MAX, 0, v}; }
/// value < v
constexpr Bounds below(double v) { return {SSX_PARAM_HAS_MAX | SSX_PARAM_MAX_OPEN, 0, v}; }
/// value > 0
constexpr Bounds positive() { return above(0); }
/// value >= 0
constexpr Bounds nonNegative() { return atLeast(0); }
/// [lo, hi]
constexpr Bounds between(double lo, double hi) { return {SSX_PARAM_HAS_MIN | SSX_PARAM_HAS_MAX, lo, hi}; }
/// Both bounds: `positive() & atMost(1)`.
constexpr Bounds operator&(Bounds a, Bounds b) {
  return {a.flags | b.flags, (b.flags & SSX_PARAM_HAS_MIN) != 0 ? b.min : a.min,
          (b.flags & SSX_PARAM_HAS_MAX) != 0 ? b.max : a.max};
}

/// A declaration of any type; the builders below fill in its type and flags.
constexpr ssx_plugin_param make(const char* name, std::uint32_t type, const char* unit, const char* default_value,
                                Bounds bounds, const char* choices, const char* doc) {
  return {name, type, bounds.flags, unit, default_value, bounds.min, bounds.max, choices, doc, nullptr};
}
/// A finite number with a unit ("" for none) and bounds.
constexpr ssx_plugin_param real(const char* name, const char* default_value, const char* unit, Bounds bounds,
                                const char* doc) {
  return make(name, SSX_PARAM_REAL, unit, default_value, bounds, "", doc);
}
/// A whole number (64 bits) with bounds.
constexpr ssx_plugin_param integer(const char* name, const char* default_value, Bounds bounds, const char* doc) {
  return make(name, SSX_PARAM_INT, "", default_value, bounds, "", doc);
}
/// A yes/no value (true/false/1/0).
constexpr ssx_plugin_param flag(const char* name, const char* default_value, const char* doc) {
  return make(name, SSX_PARAM_BOOL, "", default_value, {}, "", doc);
}
/// Any text (a name, a list of names).
constexpr ssx_plugin_param text(const char* name, const char* default_value, const char* doc) {
  return make(name, SSX_PARAM_TEXT, "", default_value, {}, "", doc);
}
/// A file the plugin writes (SSX_PARAM_OUTPUT).
constexpr ssx_plugin_param output(const char* name, const char* default_value, const char* doc) {
  ssx_plugin_param p = text(name, default_value, doc);
  p.flags |= SSX_PARAM_OUTPUT;
  return p;
}
/// A vector "x y z" with a unit; the bounds apply to each component.
constexpr ssx_plugin_param vec3(const char* name, const char* default_value, const char* unit, Bounds bounds,
                                const char* doc) {
  return make(name, SSX_PARAM_VEC3, unit, default_value, bounds, "", doc);
}
/// `choices`: the accepted words, separated by spaces.
constexpr ssx_plugin_param choice(const char* name, const char* default_value, const char* choices, const char* doc) {
  return make(name, SSX_PARAM_CHOICE, "", default_value, {}, choices, doc);
}
/// A loop rate in Hz whose period must be a whole multiple of the plugin's period (0 allowed
/// only when `bounds` allows it).
constexpr ssx_plugin_param rate(const char* name, const char* default_value, Bounds bounds, const char* doc) {
  ssx_plugin_param p = make(name, SSX_PARAM_REAL, "Hz", default_value, bounds, "", doc);
  p.flags |= SSX_PARAM_RATE;
  return p;
}
/// The same declaration, which must be given.
constexpr ssx_plugin_param required(ssx_plugin_param p) {
  p.flags |= SSX_PARAM_REQUIRED;
  return p;
}

/// A part of a class's parameters: its name and its table.
template <std::size_t N>
struct Part {
  const char* name;                     ///< the part's name ("vehicle", "controller")
  const ssx_plugin_param (&params)[N];  ///< its declarations
};
/// A part named `name` with the declarations `params` (for join).
template <std::size_t N>
constexpr Part<N> part(const char* name, const ssx_plugin_param (&params)[N]) {
  return {name, params};
}

/// The tables of a class made of parts, in order, each declaration marked with its part's name:
/// `static constexpr auto kParameters = param::join(param::part("vehicle", kVehicle), ...);`
/// (`ssx plugins --params` then prints a table per part).
template <std::size_t... N>
constexpr std::array<ssx_plugin_param, (N + ...)> join(Part<N>... parts) {
  std::array<ssx_plugin_param, (N + ...)> out{};
  std::size_t at = 0;
  (
      [&] {
        for (const ssx_plugin_param& p : parts.params) {
          out[at] = p;
          out[at].group = parts.name;
          ++at;
        }
      }(),
      ...);
  return out;
}

}  // namespace param

/// One line per declared parameter, for `ssx plugins --params` and the docs: a Markdown table
/// with the columns parameter, type, unit, default, allowed, description.
SSX_EXPORT std::string parameterTable(std::span<const ssx_plugin_param> declarations);

}  // namespace ssx
