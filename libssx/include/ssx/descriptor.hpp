#pragma once
/// @file
/// Descriptor: one node of configuration (an XML element, or built in code) with typed getters.

#include <ssx/error.hpp>
#include <ssx/export.hpp>
#include <ssx/run_files.hpp>
#include <ssx/types.hpp>

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

extern "C" struct ssx_plugin_param;

namespace ssx {

/// A node of configuration: a name, string attributes and child nodes, each with the file and
/// line it came from. Typed getters parse on demand and throw `ConfigError` naming the file,
/// line, element and attribute. Every attribute remembers whether it was read, so that unread
/// (unknown) attributes can be reported as warnings.
///
/// Supported value types: `std::string`, `bool` (true/false/1/0), `int`, `std::int64_t`,
/// `double`, `Vec3` ("x y z").
class SSX_EXPORT Descriptor {
 public:
  /// One attribute: its key, its text as written, where it was written, and whether it was read.
  struct Attribute {
    std::string key;         ///< the attribute's name
    std::string value;       ///< its text, unparsed
    SourceLocation where;    ///< file and line it came from (empty when set by code)
    mutable bool used = false;  ///< read by a getter (unread ones are reported as unknown)
  };

  Descriptor() = default;
  /// An empty node named `name` (an element name such as "driver"), from `where`.
  explicit Descriptor(std::string name, SourceLocation where = {});

  /// The element name ("driver", "sensor", "artifact", ...).
  const std::string& name() const noexcept { return name_; }
  /// The file and line the element came from (empty when made by code).
  const SourceLocation& where() const noexcept { return where_; }

  /// Sets (or replaces) an attribute; returns *this for chaining.
  Descriptor& set(std::string key, std::string value, SourceLocation where = {});
  /// Sets an attribute to a number, written so that it reads back to the same double.
  Descriptor& set(std::string key, double value);
  /// Sets an attribute to an integer.
  Descriptor& set(std::string key, std::int64_t value);
  /// @copydoc set(std::string, std::int64_t)
  Descriptor& set(std::string key, int value) { return set(std::move(key), std::int64_t{value}); }
  /// Sets an attribute to "true" or "false".
  Descriptor& set(std::string key, bool value);
  /// Sets an attribute to a text (not a bool, which a string literal would otherwise pick).
  Descriptor& set(std::string key, const char* value) { return set(std::move(key), std::string(value)); }
  /// Sets an attribute to a vector, written "x y z".
  Descriptor& set(std::string key, const Vec3& value);

  /// Removes an attribute, if there is one.
  Descriptor& erase(std::string_view key);
  /// Appends a child node and returns it.
  Descriptor& addChild(Descriptor child);

  /// Declared parameters (ssx/parameters.hpp) whose defaults `get` returns for absent
  /// attributes. The declarations must outlive this descriptor (a plugin's manifest does).
  void setDeclarations(std::span<const ssx_plugin_param> declarations) noexcept { declarations_ = declarations; }
  /// The declared parameters set by setDeclarations (empty when none).
  std::span<const ssx_plugin_param> declarations() const noexcept { return declarations_; }

  /// Whether the attribute was given (a declared default does not count).
  bool has(std::string_view key) const;
  /// The raw text of an attribute, or nullptr. Marks it read.
  const Attribute* find(std::string_view key) const;

  /// The attribute parsed as T, else its declared default; throws ConfigError if it has neither,
  /// or is malformed.
  template <class T>
  T get(std::string_view key) const;
  /// The attribute parsed as T, else its declared default, else `fallback`; throws ConfigError if
  /// malformed.
  template <class T>
  T get(std::string_view key, const T& fallback) const;
  /// An attribute's value (one of this descriptor's, or a stand-in) parsed as T; throws
  /// ConfigError naming it if malformed.
  template <class T>
  T parse(const Attribute& attribute) const;
  /// Like get, and also checks `value > 0` (throws ConfigError naming the attribute).
  double getPositive(std::string_view key, double fallback) const;

  /// Every attribute, in the order given.
  const std::vector<Attribute>& attributes() const noexcept { return attributes_; }
  /// Every child node, in document order.
  const std::vector<Descriptor>& children() const noexcept { return children_; }
  /// @copydoc children() const
  std::vector<Descriptor>& children() noexcept { return children_; }
  /// The first child with this element name, or nullptr.
  const Descriptor* child(std::string_view name) const;
  /// Every child with this element name, in document order.
  std::vector<const Descriptor*> childrenNamed(std::string_view name) const;

  /// Attributes never read, as "file:line: warning: unknown attribute 'k' of <name>" lines
  /// (this node only; callers recurse where the children are theirs).
  std::vector<std::string> unusedAttributeWarnings() const;

  /// Builds the ConfigError for this element: "file:line: error: <name>: message".
  ConfigError error(const std::string& message) const;
  /// Builds the ConfigError for one attribute of this element.
  ConfigError error(const Attribute& attribute, const std::string& message) const;
  /// Builds the ConfigError for attribute `key`: at its line when it was given, at the element's
  /// when it was not (a declared default, say).
  ConfigError errorAt(std::string_view key, const std::string& message) const;

 private:
  std::string name_;
  SourceLocation where_;
  std::vector<Attribute> attributes_;
  std::vector<Descriptor> children_;
  std::span<const ssx_plugin_param> declarations_;
  // the declared default of `key`, or null
  const char* declaredDefault(std::string_view key) const noexcept;
};

// explicit instantiations live in descriptor.cpp
/// @cond
extern template SSX_EXPORT std::string Descriptor::get<std::string>(std::string_view) const;
extern template SSX_EXPORT bool Descriptor::get<bool>(std::string_view) const;
extern template SSX_EXPORT int Descriptor::get<int>(std::string_view) const;
extern template SSX_EXPORT std::int64_t Descriptor::get<std::int64_t>(std::string_view) const;
extern template SSX_EXPORT double Descriptor::get<double>(std::string_view) const;
extern template SSX_EXPORT Vec3 Descriptor::get<Vec3>(std::string_view) const;
extern template SSX_EXPORT std::string Descriptor::get<std::string>(std::string_view, const std::string&) const;
extern template SSX_EXPORT bool Descriptor::get<bool>(std::string_view, const bool&) const;
extern template SSX_EXPORT int Descriptor::get<int>(std::string_view, const int&) const;
extern template SSX_EXPORT std::int64_t Descriptor::get<std::int64_t>(std::string_view, const std::int64_t&) const;
extern template SSX_EXPORT double Descriptor::get<double>(std::string_view, const double&) const;
extern template SSX_EXPORT Vec3 Descriptor::get<Vec3>(std::string_view, const Vec3&) const;
/// @endcond

/// An XML document as a Descriptor tree (its root element), every element and attribute with the
/// line it is on; `label` names it in messages. Throws ConfigError "label:line: error: ..." on a
/// syntax error, at the line of the problem. ssx's own files and tools read XML through it.
SSX_EXPORT Descriptor parseXml(std::string_view text, const std::string& label);

/// Reads (readInputFile: a regular file of at most `max_bytes`) and parses a file. Throws
/// ConfigError naming the file (line 0) when it cannot be read.
SSX_EXPORT Descriptor readXmlFile(const std::filesystem::path& file, std::uintmax_t max_bytes = kDefaultMaxInputBytes);

}  // namespace ssx
