// The builder's plugin checks: a plugin's parameters (a preset's first) checked against its
// class's declarations and by its own validate, the files it writes claimed with the run's other
// outputs; a placing element's parameters and period on top of its type's.
#include "scene/builder.hpp"

#include "plugin/parameter_checks.hpp"

#include <algorithm>

namespace ssx::detail {

namespace fs = std::filesystem;

void SceneBuilder::checkPlugin(Environment& env, const void* instance, Descriptor& params, const Artifact* artifact,
                              std::int64_t period_steps, const std::string& what, const SourceLocation& period_from,
                              const PluginDeclaration* decl, const Descriptor* overrides) {
  const ssx_plugin_class* type = env.classLoader().classOf(instance);
  if (type == nullptr) return;
  const std::span<const ssx_plugin_param> declarations{type->params, type->param_count};
  // a preset's values first: then they are checked as the element's own (the preset file is an input)
  if (!presets_) {
    std::vector<fs::path> dirs;
    for (const fs::path& d : options_.artifact_path) dirs.push_back(d / "presets");
    if (options_.search_installed_artifacts)
      if (fs::path installed = Presets::installedDirectory(); !installed.empty()) dirs.push_back(installed);
    presets_.emplace(std::move(dirs), options_.max_input_bytes);
  }
  fs::path preset_file;
  if (auto problems = presets_->apply(params, type->name, declarations, what, &preset_file); !problems.empty()) {
    // (once: a swarm's members share the preset, and its problem)
    for (auto& d : problems)
      if (reported_presets_.insert(d.str()).second) log_.add(std::move(d));
    for (const auto& a : params.attributes()) a.used = true;
    params.setDeclarations(declarations);
    return;
  }
  if (!preset_file.empty()) files_.addInput(preset_file);
  // the declared checks read only the values, the period and the time step: once the parameters
  // of a declaration and a placing element passed, the next member of that swarm differs only in
  // the values where its index was put ({i}), and only those need checking
  const auto key = std::make_tuple(static_cast<const void*>(type), decl, overrides, period_steps);
  const auto clean = decl != nullptr ? clean_checks_.find(key) : clean_checks_.end();
  const PluginContext context{&env, artifact, period_steps, env.timestep(), period_from};
  std::vector<Diagnostic> found = detail::checkParametersNamed(
      declarations, params, context, what, clean != clean_checks_.end() ? &clean->second : nullptr);
  if (decl != nullptr && clean == clean_checks_.end() && found.empty()) {
    std::vector<std::string> per_member;
    if (overrides != nullptr)
      for (const auto& a : overrides->attributes())
        if (a.value.find("{i}") != std::string::npos) per_member.push_back(a.key);
    // (a preset that differs between members brings values that differ: each member checked whole)
    if (std::find(per_member.begin(), per_member.end(), "preset") == per_member.end())
      clean_checks_.emplace(key, std::move(per_member));
  }
  // the files it writes, with the run's others (only when its values are of the declared types)
  if (found.empty())
    for (const ssx_plugin_param& p : declarations) {
      if ((p.flags & SSX_PARAM_OUTPUT) == 0) continue;
      const auto* a = params.find(p.name);
      if (a == nullptr || a->value.empty()) continue;
      const SourceLocation where = a->where;
      std::string file = a->value;
      const bool moved = !options_.output_directory.empty() && fs::path(file).is_relative();
      // (the program makes the output directory after loading; deeper directories must exist)
      const bool in_made_directory = moved && fs::path(file).parent_path().empty();
      if (moved) {
        // into the run's output directory: the plugin opens it there
        file = (options_.output_directory / file).string();
        params.set(p.name, file, where);
      }
      if (auto problem = files_.claimOutput(file, "parameter '" + std::string(p.name) + "'", false, in_made_directory); !problem.empty())
        found.push_back({Diagnostic::Severity::Error, where, "<" + params.name() + ">: " + what + ": " + problem});
    }
  for (auto& d : found) log_.add(std::move(d));
  // unknown parameters were reported just now: not again when the environment starts
  for (const auto& a : params.attributes()) a.used = true;
}

void SceneBuilder::validatePlugin(Environment& env, const void* instance, const Descriptor& params,
                                 const Artifact* artifact, std::int64_t period_steps, const std::string& what) {
  const ssx_plugin_class* type = env.classLoader().classOf(instance);
  if (type == nullptr || type->validate == nullptr) return;
  const PluginContext context{&env, artifact, period_steps, env.timestep(), {}, &validate_shared_[type]};
  std::vector<Diagnostic> found;
  type->validate(&params, &context, &found);
  for (auto& d : found) {
    // named as the declared checks name it: "<driver>: driver 'quadrotor': ..."
    const std::string element = "<" + params.name() + ">: ";
    if (d.message.rfind(element, 0) == 0) d.message.erase(0, element.size());
    d.message = element + what + ": " + d.message;
    log_.add(std::move(d));
  }
}

Descriptor SceneBuilder::withOverrides(const PluginDeclaration& decl, const Descriptor* overrides, const std::string& index) {
  if (overrides == nullptr) return decl.params;
  Descriptor params = decl.params;
  for (const auto& a : overrides->attributes()) {
    if (a.key == "index" || a.key == "period") continue;  // read by the loader, not plugin parameters
    // in a swarm, {i} in a value is the member's index
    std::string value = a.value;
    if (!index.empty())
      for (auto at = value.find("{i}"); at != std::string::npos; at = value.find("{i}", at + index.size()))
        value.replace(at, 3, index);
    params.set(a.key, value, a.where);
  }
  return params;
}

std::int64_t SceneBuilder::periodOf(const PluginDeclaration& decl, const Descriptor* overrides) {
  if (overrides == nullptr || !overrides->has("period")) return decl.period;
  // (the reader leaves out a period it reported: this one is from a model made in code)
  try {
    const auto steps = overrides->get<std::int64_t>("period");
    if (steps >= 1) return steps;
    error(overrides->find("period")->where,
          "<" + overrides->name() + ">: attribute 'period' must be at least 1, got " + std::to_string(steps));
  } catch (const ConfigError& e) {
    error(e.where(), e.detail());
  }
  return decl.period;
}

SourceLocation SceneBuilder::periodFrom(const PluginDeclaration& decl, const Descriptor* overrides) {
  if (overrides != nullptr)
    if (const auto* a = overrides->find("period")) return a->where;
  return decl.period_from;
}

}  // namespace ssx::detail
