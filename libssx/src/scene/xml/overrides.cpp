// Attribute overrides: a path of element steps and an attribute, set in a scene file's tree
// before it is read (see AttributeOverride in ssx/scene.hpp).
#include "scene/xml/scene_loader.hpp"

#include <charconv>

namespace ssx::detail {

namespace {

struct Step {
  std::string name;
  std::size_t nth = 0;  // [k], from 1; 0: none
  std::string key, value;  // [key=value]
  std::string text;
};

std::optional<Step> parseStep(std::string_view text) {
  Step s;
  s.text = std::string(text);
  const auto open = text.find('[');
  s.name = std::string(text.substr(0, open));
  if (s.name.empty()) return std::nullopt;
  if (open == std::string_view::npos) return s;
  if (text.back() != ']') return std::nullopt;
  const std::string_view inner = text.substr(open + 1, text.size() - open - 2);
  if (const auto eq = inner.find('='); eq != std::string_view::npos) {
    s.key = std::string(inner.substr(0, eq));
    s.value = std::string(inner.substr(eq + 1));
    return s.key.empty() ? std::nullopt : std::optional<Step>(s);
  }
  const auto [end, ec] = std::from_chars(inner.data(), inner.data() + inner.size(), s.nth);
  if (ec != std::errc() || end != inner.data() + inner.size() || s.nth == 0) return std::nullopt;
  return s;
}

bool matches(const Descriptor& d, const Step& s) {
  if (d.name() != s.name) return false;
  if (s.key.empty()) return true;
  const Descriptor::Attribute* a = d.find(s.key);
  return a != nullptr && a->value == s.value;
}

}  // namespace

std::optional<std::string> applyOverride(Descriptor& scene, const AttributeOverride& o, std::string* identity) {
  const std::string syntax = "target '" + o.target +
                             "' is not a path like swarm[name=quad{i}]/driver@formation_gain (steps name, "
                             "name[k] or name[attribute=value] separated by '/', then @attribute)";
  const auto at = o.target.rfind('@');
  if (at == std::string::npos || at == 0 || at + 1 == o.target.size()) return syntax;
  const std::string attribute = o.target.substr(at + 1);
  std::vector<Step> steps;
  for (std::size_t begin = 0; begin < at;) {
    const auto slash = std::min(o.target.find('/', begin), at);
    auto step = parseStep(std::string_view(o.target).substr(begin, slash - begin));
    if (!step) return syntax;
    steps.push_back(std::move(*step));
    begin = slash + 1;
  }
  Descriptor* node = &scene;
  std::string path = "<scene>";
  std::string indices;  // the element by its child indices: the same element however the target spells it
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const Step& s = steps[i];
    std::vector<Descriptor*> found;
    std::size_t same_name = 0;
    for (Descriptor& c : node->children()) {
      if (c.name() == s.name) ++same_name;
      if (!matches(c, s)) continue;
      if (s.nth == 0 || same_name == s.nth) found.push_back(&c);
    }
    if (found.size() == 1) {
      indices += std::to_string(found.front() - node->children().data()) + "/";
      node = found.front();
      path += " <" + s.text + ">";
      continue;
    }
    if (found.size() > 1)
      return "target '" + o.target + "': '" + s.text + "' matches " + std::to_string(found.size()) + " elements in " +
             path + "; pick one with " + s.name + "[k] or " + s.name + "[name=...]";
    // a placement's plugin element, or one of the scene's settings elements, that is not there yet
    // is added
    const bool placement = node->name() == "artifact" || node->name() == "swarm";
    const bool settings = i == 0 && s.key.empty() &&
                          (s.name == "environment" || s.name == "physics" || s.name == "render");
    const bool addable = i + 1 == steps.size() && s.nth == 0 &&
                         (settings || (placement && ((s.name == "driver" && s.key.empty()) ||
                                                     (s.name == "sensor" && s.key == "index"))));
    if (!addable)
      return "target '" + o.target + "': no element '" + s.text + "' in " + path + " (" +
             (same_name > 0 ? std::to_string(same_name) + " <" + s.name + "> there, none that fits"
                            : std::string("it has none of that name")) +
             ")";
    Descriptor added(s.name, o.where);
    if (!s.key.empty()) added.set(s.key, s.value, o.where);
    indices += std::to_string(node->children().size()) + "/";
    node = &node->addChild(std::move(added));
    path += " <" + s.text + ">";
  }
  node->set(attribute, o.value, o.where);
  if (identity != nullptr) *identity = indices + "@" + attribute;
  return std::nullopt;
}

}  // namespace ssx::detail
