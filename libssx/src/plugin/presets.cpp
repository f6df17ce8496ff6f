#include "plugin/presets.hpp"
#include "plugin/parameter_checks.hpp"

#include <ssx/parameters.hpp>
#include <ssx/run_files.hpp>
#include <ssx/scene.hpp>

#include <algorithm>
#include <set>

namespace ssx::detail {

namespace fs = std::filesystem;

namespace {

// a value naming a file rather than a preset by name
bool isPath(const std::string& value) {
  return value.find('/') != std::string::npos || (value.size() > 4 && value.ends_with(".xml"));
}

}  // namespace

Presets::Presets(std::vector<fs::path> dirs, std::uintmax_t max_bytes)
    : dirs_(std::move(dirs)), max_bytes_(max_bytes) {}

fs::path Presets::installedDirectory() {
  const fs::path data = installedDataDirectory();
  return data.empty() ? fs::path() : data / "presets";
}

std::vector<std::string> Presets::available(const std::string& class_name) const {
  std::set<std::string> names;
  for (const fs::path& dir : dirs_) {
    std::error_code ec;
    for (fs::directory_iterator it(dir / class_name, ec), end; !ec && it != end; it.increment(ec))
      if (it->path().extension() == ".xml" && it->is_regular_file(ec)) names.insert(it->path().stem().string());
  }
  return {names.begin(), names.end()};
}

const Presets::File& Presets::read(const fs::path& file, const std::string& family) {
  // (by file and family: one file asked for by two families is right for at most one)
  const std::string key = file.string() + '\n' + family;
  if (auto it = cache_.find(key); it != cache_.end()) return it->second;
  File& f = cache_[key];
  auto fail = [&](const SourceLocation& where, const std::string& message) -> const File& {
    f.values.clear();
    f.problem = message;
    f.problem_at = where;
    return f;
  };
  Descriptor root;
  try {
    root = readXmlFile(file, max_bytes_);
  } catch (const ConfigError& e) {
    return fail(e.where().file.empty() ? SourceLocation{file.string(), 0} : e.where(), e.detail());
  }
  if (root.name() != "preset") {
    return fail(root.where(), "the root element of a preset file must be <preset class=\"" + family + "\">, got <" +
                                  root.name() + ">");
  }
  const auto* of = root.find("class");
  if (of == nullptr || of->value != family) {
    return fail(of != nullptr ? of->where : root.where(), "this preset is for '" +
                                                              (of != nullptr ? of->value : std::string()) + "', not '" +
                                                              family + "': say <preset class=\"" + family + "\">");
  }
  for (const auto& a : root.attributes())
    if (a.key != "class") return fail(a.where, "<preset>: unknown attribute '" + a.key + "' (it has only 'class')");
  std::set<std::string> seen;
  for (const Descriptor& c : root.children()) {
    if (c.name() != "param")
      return fail(c.where(),
                  "unknown element <" + c.name() + "> in <preset> (it holds <param name=\"...\" value=\"...\"/>)");
    const auto* name = c.find("name");
    const auto* value = c.find("value");
    if (name == nullptr || value == nullptr) return fail(c.where(), "<param>: needs 'name' and 'value'");
    for (const auto& a : c.attributes())
      if (a.key != "name" && a.key != "value")
        return fail(a.where, "<param>: unknown attribute '" + a.key + "' (it has 'name' and 'value')");
    if (name->value == "preset") return fail(name->where, "<param>: a preset does not name another preset");
    if (!seen.insert(name->value).second)
      return fail(name->where, "<param>: '" + name->value + "' is given twice in this preset");
    // (where the value was written: an error in it names the line of the preset)
    f.values.push_back({name->value, value->value, value->where, false});
  }
  return f;
}

std::vector<Diagnostic> Presets::apply(Descriptor& params, const char* class_name,
                                       std::span<const ssx_plugin_param> declarations, const std::string& what,
                                       fs::path* used) {
  const auto declared = std::find_if(declarations.begin(), declarations.end(),
                                     [](const ssx_plugin_param& d) { return std::string_view(d.name) == "preset"; });
  if (declared == declarations.end()) return {};
  // the family: the declaration's `choices` (a class flying another's vehicle shares its presets),
  // else the class
  const std::string cls = declared->choices != nullptr && declared->choices[0] != '\0' ? declared->choices
                          : class_name != nullptr                                      ? class_name
                                                                                       : "";
  const Descriptor::Attribute* given = params.find("preset");
  const std::string name = given != nullptr ? given->value : (declared->default_value ? declared->default_value : "");
  if (name.empty()) return {};
  const SourceLocation where = given != nullptr ? given->where : params.where();
  auto error = [&](const SourceLocation& at, const std::string& message) {
    return std::vector<Diagnostic>{
        {Diagnostic::Severity::Error, at, "<" + params.name() + ">: " + what + ": " + message}};
  };

  fs::path file;
  if (isPath(name)) {
    file = name;
    if (file.is_relative() && given != nullptr && !given->where.file.empty())
      file = fs::path(given->where.file).parent_path() / file;
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) return error(where, "preset file '" + file.string() + "' not found");
  } else {
    std::string looked;
    for (const fs::path& dir : dirs_) {
      std::error_code ec;
      const fs::path candidate = dir / cls / (name + ".xml");
      if (fs::is_regular_file(candidate, ec)) {
        file = candidate;
        break;
      }
      looked += (looked.empty() ? "" : ", ") + (dir / cls).string();
    }
    // the class's default preset, not found (a libssx without its data directory): the class's
    // own defaults, which the default preset's file only writes out
    if (file.empty() && given == nullptr) return {};
    if (file.empty()) {
      std::string known;
      for (const std::string& k : available(cls)) known += (known.empty() ? "" : ", ") + k;
      return error(where, "no preset '" + name + "' for " + cls + " (looked for " + name + ".xml in " +
                              (looked.empty() ? std::string("no directory") : looked) + "; " +
                              (known.empty() ? std::string("none there") : "there are: " + known) +
                              "); give a preset file's path, e.g. preset=\"presets/" + name + ".xml\"");
    }
  }
  file = fs::absolute(file).lexically_normal();
  const File& f = read(file, cls);
  if (!f.problem.empty()) return error(f.problem_at, "preset '" + name + "': " + f.problem);
  // every value is one of the class's parameters; a class sharing another's presets takes those
  // it declares
  const bool own = cls == (class_name != nullptr ? class_name : "");
  std::vector<std::string> names;
  for (const ssx_plugin_param& d : declarations) names.emplace_back(d.name);
  for (const auto& v : f.values)
    if (own && !declares(declarations, v.key))
      return error(v.where, "preset '" + name + "': <param>: '" + v.key + "' is not a parameter of " + cls +
                                didYouMean(v.key, names) + " (`ssx plugins --params " + cls + "` lists them)");
  for (const auto& v : f.values)
    if (!params.has(v.key) && declares(declarations, v.key)) params.set(v.key, v.value, v.where);
  if (used != nullptr) *used = file;
  return {};
}

std::vector<Diagnostic> Presets::checkInstance(Descriptor& params, const ssx_plugin_class& type,
                                               const PluginContext& context, const std::string& what) {
  const std::span<const ssx_plugin_param> declarations{type.params, type.param_count};
  std::vector<Diagnostic> found = apply(params, type.name, declarations, what);
  if (found.empty()) found = checkParameters(declarations, params, context, what);
  // the class's own checks only for parameters that passed the declared ones
  const bool declared_ok = std::none_of(found.begin(), found.end(), [](const Diagnostic& d) {
    return d.severity == Diagnostic::Severity::Error;
  });
  if (declared_ok && type.validate != nullptr) {
    std::vector<Diagnostic> own;
    type.validate(&params, &context, &own);
    for (auto& d : own) d.message = what + ": " + d.message;
    found.insert(found.end(), own.begin(), own.end());
  }
  return found;
}

Presets Presets::installed() {
  std::vector<fs::path> dirs;
  if (fs::path dir = installedDirectory(); !dir.empty()) dirs.push_back(std::move(dir));
  return Presets(std::move(dirs), kDefaultMaxInputBytes);
}

}  // namespace ssx::detail
