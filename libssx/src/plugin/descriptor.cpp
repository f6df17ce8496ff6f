#include <ssx/descriptor.hpp>
#include <ssx/parameters.hpp>

#include <charconv>
#include <cstring>
#include <cctype>
#include <cmath>

namespace ssx {

namespace {

// parse helpers: each returns false when the text is not a complete value of the type
bool parseValue(const std::string& text, std::string& out) {
  out = text;
  return true;
}

bool parseValue(const std::string& text, bool& out) {
  if (text == "true" || text == "1") {
    out = true;
    return true;
  }
  if (text == "false" || text == "0") {
    out = false;
    return true;
  }
  return false;
}

// std::from_chars: what users write (1e-3, .5, +2, surrounding spaces), independent of the
// process's locale (strtod would read "0.5" as 0 under a decimal comma); out of range is no number
template <class Number>
bool parseNumber(const std::string& text, Number& out) {
  const char* begin = text.data();
  const char* end = begin + text.size();
  while (begin < end && *begin == ' ') ++begin;
  while (end > begin && end[-1] == ' ') --end;
  if (begin < end && *begin == '+') ++begin;
  auto [ptr, ec] = std::from_chars(begin, end, out);
  return ec == std::errc() && ptr == end && begin != end;
}

bool parseValue(const std::string& text, int& out) { return parseNumber(text, out); }
bool parseValue(const std::string& text, std::int64_t& out) { return parseNumber(text, out); }
bool parseValue(const std::string& text, double& out) { return parseNumber(text, out) && std::isfinite(out); }

bool parseValue(const std::string& text, Vec3& out) {
  // three words separated by white space, each a complete number (no stream: a swarm's members
  // each parse their vectors while loading)
  std::string word;
  std::size_t at = 0;
  for (int i = 0; i < 3; ++i) {
    while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at])) != 0) ++at;
    const std::size_t begin = at;
    while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at])) == 0) ++at;
    if (begin == at) return false;
    word.assign(text, begin, at - begin);
    if (!parseValue(word, out[i])) return false;
  }
  while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at])) != 0) ++at;
  return at == text.size();
}

template <class T>
const char* typeName();
template <>
const char* typeName<std::string>() {
  return "a string";
}
template <>
const char* typeName<bool>() {
  return "a boolean (true or false)";
}
template <>
const char* typeName<int>() {
  return "an integer";
}
template <>
const char* typeName<std::int64_t>() {
  return "an integer";
}
template <>
const char* typeName<double>() {
  return "a finite number";
}
template <>
const char* typeName<Vec3>() {
  return "three numbers \"x y z\"";
}

std::string formatNumber(double v) {
  // the shortest text that reads back as the same double, whatever the locale
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
  return ec == std::errc() ? std::string(text, end) : std::string("nan");
}

}  // namespace

Descriptor::Descriptor(std::string name, SourceLocation where) : name_(std::move(name)), where_(std::move(where)) {}

Descriptor& Descriptor::erase(std::string_view key) {
  std::erase_if(attributes_, [&](const Attribute& a) { return a.key == key; });
  return *this;
}

Descriptor& Descriptor::set(std::string key, std::string value, SourceLocation where) {
  if (where.file.empty()) where = where_;
  for (auto& a : attributes_) {
    if (a.key == key) {
      a.value = std::move(value);
      a.where = std::move(where);
      a.used = false;
      return *this;
    }
  }
  attributes_.push_back({std::move(key), std::move(value), std::move(where), false});
  return *this;
}

Descriptor& Descriptor::set(std::string key, double value) { return set(std::move(key), formatNumber(value)); }
Descriptor& Descriptor::set(std::string key, std::int64_t value) { return set(std::move(key), std::to_string(value)); }
Descriptor& Descriptor::set(std::string key, bool value) {
  return set(std::move(key), std::string(value ? "true" : "false"));
}
Descriptor& Descriptor::set(std::string key, const Vec3& v) {
  return set(std::move(key), formatNumber(v.x()) + " " + formatNumber(v.y()) + " " + formatNumber(v.z()));
}

Descriptor& Descriptor::addChild(Descriptor child) {
  children_.push_back(std::move(child));
  return children_.back();
}

bool Descriptor::has(std::string_view key) const {
  for (const auto& a : attributes_)
    if (a.key == key) return true;
  return false;
}

const Descriptor::Attribute* Descriptor::find(std::string_view key) const {
  for (const auto& a : attributes_) {
    if (a.key == key) {
      a.used = true;
      return &a;
    }
  }
  return nullptr;
}

const char* Descriptor::declaredDefault(std::string_view key) const noexcept {
  // (a plugin declares dozens of parameters and every swarm member reads each: no strlen per name)
  for (const auto& d : declarations_)
    if (!key.empty() && d.name[0] == key[0] && std::strncmp(d.name, key.data(), key.size()) == 0 &&
        d.name[key.size()] == '\0')
      return d.default_value != nullptr && d.default_value[0] != '\0' ? d.default_value : nullptr;
  return nullptr;
}

namespace {
// a plugin's declared default for `key`, parsed
template <class T>
T parseDefault(const Descriptor& d, std::string_view key, const char* text) {
  T value{};
  if (!parseValue(text, value))
    throw d.error("the declared default of '" + std::string(key) + "' ('" + text + "') is not " + typeName<T>() +
                  " (a bug in the plugin's declarations)");
  return value;
}
}  // namespace

template <class T>
T Descriptor::get(std::string_view key) const {
  if (const Attribute* a = find(key)) return parse<T>(*a);
  const char* fallback = declaredDefault(key);
  if (fallback == nullptr) throw error("missing attribute '" + std::string(key) + "'");
  return parseDefault<T>(*this, key, fallback);
}

template <class T>
T Descriptor::get(std::string_view key, const T& fallback) const {
  if (const Attribute* a = find(key)) return parse<T>(*a);
  const char* declared = declaredDefault(key);
  return declared != nullptr ? parseDefault<T>(*this, key, declared) : fallback;
}

template <class T>
T Descriptor::parse(const Attribute& a) const {
  T value{};
  if (!parseValue(a.value, value))
    throw error(a, "attribute '" + a.key + "' must be " + typeName<T>() + ", got '" + a.value + "'");
  return value;
}

double Descriptor::getPositive(std::string_view key, double fallback) const {
  const double v = get<double>(key, fallback);
  if (!(v > 0.0)) {
    const Attribute* a = find(key);
    const std::string message = "attribute '" + std::string(key) + "' must be positive, got " + formatNumber(v);
    throw a != nullptr ? error(*a, message) : error(message);
  }
  return v;
}

const Descriptor* Descriptor::child(std::string_view name) const {
  for (const auto& c : children_)
    if (c.name_ == name) return &c;
  return nullptr;
}

std::vector<const Descriptor*> Descriptor::childrenNamed(std::string_view name) const {
  std::vector<const Descriptor*> out;
  for (const auto& c : children_)
    if (c.name_ == name) out.push_back(&c);
  return out;
}

std::vector<std::string> Descriptor::unusedAttributeWarnings() const {
  std::vector<std::string> out;
  for (const auto& a : attributes_)
    if (!a.used) out.push_back(a.where.str() + ": warning: unknown attribute '" + a.key + "' of <" + name_ + ">");
  return out;
}

ConfigError Descriptor::error(const std::string& message) const {
  return ConfigError(where_, "<" + name_ + ">: " + message);
}

ConfigError Descriptor::error(const Attribute& attribute, const std::string& message) const {
  return ConfigError(attribute.where, "<" + name_ + ">: " + message);
}

ConfigError Descriptor::errorAt(std::string_view key, const std::string& message) const {
  const Attribute* a = find(key);
  return a != nullptr ? error(*a, message) : error(message);
}

#define SSX_INSTANTIATE_GET(T)                                                \
  template SSX_EXPORT T Descriptor::get<T>(std::string_view) const;           \
  template SSX_EXPORT T Descriptor::get<T>(std::string_view, const T&) const; \
  template SSX_EXPORT T Descriptor::parse<T>(const Attribute&) const;
SSX_INSTANTIATE_GET(std::string)
SSX_INSTANTIATE_GET(bool)
SSX_INSTANTIATE_GET(int)
SSX_INSTANTIATE_GET(std::int64_t)
SSX_INSTANTIATE_GET(double)
SSX_INSTANTIATE_GET(Vec3)
#undef SSX_INSTANTIATE_GET

}  // namespace ssx
