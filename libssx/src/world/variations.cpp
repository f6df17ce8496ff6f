// Constants varied between steps (Environment::vary, ssx/variation.hpp): a learning
// environment's domain randomisation. The world keeps every value other than the neutral one,
// per artifact and sorted, so a saved state holds the same bytes whatever order they were set in,
// and restoring a state sets each constant to the state's value.
#include "world/phases.hpp"
#include "world/world.hpp"

#include <ssx/environment.hpp>
#include <ssx/error.hpp>
#include <ssx/variation.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace ssx {

VariationInterface::~VariationInterface() = default;

namespace {

// the variables the Environment itself gives every artifact with a moving body
constexpr Variable kBodyVariables[] = {
    {"mass", 1.0, 0.05, 20.0, "factor on each body's mass"},
    {"inertia", 1.0, 0.05, 20.0, "factor on each body's inertia about its centre of mass"},
};

Plugin* pluginAt(const detail::World& w, std::size_t artifact, std::int32_t index) {
  const detail::ArtifactData& a = w.artifact_data[artifact];
  if (index == 0) return a.driver;
  const auto sensor = static_cast<std::size_t>(index - 1);
  return sensor < a.sensors.size() ? a.sensors[sensor].sensor : nullptr;
}

// the variables of an artifact's plugin `index` (-1: its bodies); empty when it has none
std::span<const Variable> variablesOf(const detail::World& w, std::size_t artifact, std::int32_t index) {
  if (index < 0) {  // a moving body: a dynamic root (known before start, when the bodies are made)
    const Artifact& a = *w.artifacts[artifact];
    for (std::size_t r = 0; r < a.rootCount(); ++r)
      if (!a.root(r).isStatic()) return kBodyVariables;
    return {};
  }
  const auto* v = dynamic_cast<const VariationInterface*>(pluginAt(w, artifact, index));
  return v != nullptr ? v->variables() : std::span<const Variable>();
}

std::int32_t pluginCount(const detail::World& w, std::size_t artifact) {
  return static_cast<std::int32_t>(w.artifact_data[artifact].sensors.size()) + 1;
}

struct Found {
  std::int32_t plugin = -1;
  std::uint32_t k = 0;
  const Variable* variable = nullptr;
};

Found find(const detail::World& w, std::size_t artifact, std::string_view name) {
  for (std::int32_t p = -1; p < pluginCount(w, artifact); ++p) {
    const auto vars = variablesOf(w, artifact, p);
    for (std::size_t k = 0; k < vars.size(); ++k)
      if (name == vars[k].name) return {p, static_cast<std::uint32_t>(k), &vars[k]};
  }
  return {};
}

double valueOf(const detail::World& w, std::size_t artifact, std::int32_t plugin, std::uint32_t k, double neutral) {
  if (w.varied.empty()) return neutral;
  for (const detail::Varied& v : w.varied[artifact])
    if (v.plugin == plugin && v.k == k) return v.value;
  return neutral;
}

void applyMass(const detail::World& w, std::size_t artifact, PhysicEngine& engine) {
  const double mass = valueOf(w, artifact, -1, 0, 1.0), inertia = valueOf(w, artifact, -1, 1, 1.0);
  const detail::ArtifactData& a = w.artifact_data[artifact];
  for (int b = a.body_begin; b < a.body_end; ++b) engine.setMassScale(b, mass, inertia);
}

// records the value (dropping it when neutral), keeping the artifact's list sorted
void record(detail::World& w, std::size_t artifact, const detail::Varied& entry, double neutral) {
  if (w.varied.empty()) w.varied.resize(w.artifacts.size());
  auto& list = w.varied[artifact];
  const auto at =
      std::lower_bound(list.begin(), list.end(), entry, [](const detail::Varied& a, const detail::Varied& b) {
        return a.plugin != b.plugin ? a.plugin < b.plugin : a.k < b.k;
      });
  const bool present = at != list.end() && at->plugin == entry.plugin && at->k == entry.k;
  if (entry.value == neutral) {
    if (present) list.erase(at);
  } else if (present) {
    at->value = entry.value;
  } else {
    list.insert(at, entry);
  }
}

// sets the constant in its plugin (or the bodies' masses) to what World::varied now says
void apply(detail::World& w, std::size_t artifact, std::int32_t plugin, std::uint32_t k, double value) {
  if (plugin < 0)
    applyMass(w, artifact, *w.engine);
  else
    dynamic_cast<VariationInterface*>(pluginAt(w, artifact, plugin))->vary(k, value);
}

}  // namespace

std::vector<Variable> Environment::variables(const Artifact& artifact) const {
  std::vector<Variable> out;
  const detail::World& w = *world_;
  for (std::int32_t p = -1; p < pluginCount(w, artifact.index()); ++p)
    for (const Variable& v : variablesOf(w, artifact.index(), p))
      if (std::none_of(out.begin(), out.end(), [&](const Variable& o) { return std::string_view(o.name) == v.name; }))
        out.push_back(v);
  return out;
}

void Environment::vary(const Artifact& artifact, std::string_view name, double value) {
  requireOutsidePhases("vary");
  detail::World& w = *world_;
  if (w.state != State::Running) throw Error("vary: the environment is not running (start it first)");
  const std::size_t a = artifact.index();
  const Found f = find(w, a, name);
  if (f.variable == nullptr) {
    std::ostringstream m;
    m << "vary: artifact '" << artifact.name() << "' has no constant '" << name << "' that can vary (it has: ";
    const auto known = variables(artifact);
    for (std::size_t i = 0; i < known.size(); ++i) m << (i ? ", " : "") << known[i].name;
    m << (known.empty() ? "none)" : ")");
    throw ConfigError({}, m.str());
  }
  if (!std::isfinite(value) || value < f.variable->min || value > f.variable->max) {
    std::ostringstream m;
    m << "vary: " << name << " of artifact '" << artifact.name() << "' must be within [" << f.variable->min << ", "
      << f.variable->max << "] (" << f.variable->doc << "), got " << value;
    throw ConfigError({}, m.str());
  }
  record(w, a, {f.plugin, f.k, value}, f.variable->neutral);
  apply(w, a, f.plugin, f.k, value);
  rays_stale_ = true;
}

double Environment::variation(const Artifact& artifact, std::string_view name) const {
  const Found f = find(*world_, artifact.index(), name);
  if (f.variable == nullptr)
    throw ConfigError(
        {}, "variation: artifact '" + artifact.name() + "' has no constant '" + std::string(name) + "' that can vary");
  return valueOf(*world_, artifact.index(), f.plugin, f.k, f.variable->neutral);
}

namespace detail {

void saveVariations(const World& w, StateWriter& out) {
  std::uint64_t artifacts = 0;
  for (const auto& list : w.varied) artifacts += list.empty() ? 0 : 1;
  out.write(artifacts);
  for (std::size_t a = 0; a < w.varied.size(); ++a) {
    if (w.varied[a].empty()) continue;
    out.write(static_cast<std::uint32_t>(a));
    out.write(static_cast<std::uint64_t>(w.varied[a].size()));
    for (const Varied& v : w.varied[a]) {
      out.write(v.plugin);
      out.write(v.k);
      out.write(v.value);
    }
  }
}

void loadVariations(World& w, StateReader& in) {
  // read and check everything first: the world's constants change only for a state that fits
  std::vector<std::vector<Varied>> next(w.artifacts.size());
  const std::size_t artifacts = in.count(4 + 8);
  for (std::size_t i = 0; i < artifacts; ++i) {
    const auto a = in.get<std::uint32_t>();
    if (a >= w.artifacts.size() || !next[a].empty())
      throw StateError("saved state: varied constants of artifact " + std::to_string(a) +
                       " that does not fit (corrupted)");
    const std::size_t n = in.count(4 + 4 + 8);
    for (std::size_t j = 0; j < n; ++j) {
      Varied v;
      in.read(v.plugin);
      in.read(v.k);
      in.read(v.value);
      const auto vars =
          v.plugin >= -1 && v.plugin < pluginCount(w, a) ? variablesOf(w, a, v.plugin) : std::span<const Variable>();
      const bool sorted = next[a].empty() || next[a].back().plugin < v.plugin ||
                          (next[a].back().plugin == v.plugin && next[a].back().k < v.k);
      if (v.k >= vars.size() || !sorted || !std::isfinite(v.value) || v.value < vars[v.k].min ||
          v.value > vars[v.k].max || v.value == vars[v.k].neutral)
        throw StateError("saved state: a varied constant of artifact '" + w.artifacts[a]->name() +
                         "' that fits none of its variables (corrupted, or saved from another build of its plugins)");
      next[a].push_back(v);
    }
  }
  // back to neutral what the state does not vary, then the state's values
  std::vector<std::vector<Varied>> previous = std::move(w.varied);
  w.varied = std::move(next);
  bool any = false;
  for (std::size_t a = 0; a < previous.size(); ++a)
    for (const Varied& v : previous[a]) {
      const double value = valueOf(w, a, v.plugin, v.k, variablesOf(w, a, v.plugin)[v.k].neutral);
      if (value != v.value || v.plugin < 0) apply(w, a, v.plugin, v.k, value);
    }
  for (std::size_t a = 0; a < w.varied.size(); ++a)
    for (const Varied& v : w.varied[a]) {
      apply(w, a, v.plugin, v.k, v.value);
      any = true;
    }
  if (!any) w.varied.clear();
}

void applyMassScales(const World& w, PhysicEngine& engine) {
  for (std::size_t a = 0; a < w.varied.size(); ++a)
    if (!w.varied[a].empty() && w.varied[a].front().plugin < 0) applyMass(w, a, engine);
}

}  // namespace detail

}  // namespace ssx
