#pragma once
/// @file
/// The errors ssx reports. Every message is complete and says what to do.

#include <ssx/export.hpp>

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace ssx {

/// Where a piece of configuration came from: a file and a 1-based line, or code.
struct SourceLocation {
  std::string file;  ///< empty when built in code
  int line = 0;      ///< 1-based; 0 when unknown

  /// "file:line", "file", or "<code>".
  SSX_EXPORT std::string str() const;
};

/// The name among `candidates` nearest to `name` (fewest single-character edits, case ignored), if it
/// is near enough to be a typing slip (at most a third of its length, and 1 for short names):
/// " (did you mean 'csv_logger'?)", else an empty string. For messages about unknown names.
SSX_EXPORT std::string didYouMean(std::string_view name, const std::vector<std::string>& candidates);
/// The candidate itself, or an empty string.
SSX_EXPORT std::string nearestName(std::string_view name, const std::vector<std::string>& candidates);

/// Base of every ssx exception.
class SSX_EXPORT Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad configuration: a scene, an artifact, a parameter. The message reads
/// `file:line: error: ...` when the location is known.
class SSX_EXPORT ConfigError : public Error {
 public:
  /// An error at `where`; what() is "file:line: error: message" ("<code>: error: message" when
  /// `where` is empty: SourceLocation::str).
  ConfigError(SourceLocation where, const std::string& message);
  /// Where the bad input is (empty when not known).
  const SourceLocation& where() const noexcept { return where_; }
  /// The message without the location prefix.
  const std::string& detail() const noexcept { return detail_; }

 private:
  SourceLocation where_;
  std::string detail_;
};

/// A step was abandoned: a plugin threw, or the physics produced a NaN or infinite state.
/// The environment is left in the failed state: it refuses further steps.
class SSX_EXPORT StepError : public Error {
 public:
  /// The failure `what` of `plugin` of `artifact` in step `step`; what() names all four.
  StepError(std::string artifact, std::string plugin, std::int64_t step, const std::string& what);
  /// Name of the artifact whose plugin or state failed.
  const std::string& artifact() const noexcept { return artifact_; }
  /// Which plugin failed: "driver <class>", "sensor <index> <class>", or "physics".
  const std::string& plugin() const noexcept { return plugin_; }
  /// Index of the step that was abandoned.
  std::int64_t step() const noexcept { return step_; }

 private:
  std::string artifact_;
  std::string plugin_;
  std::int64_t step_;
};

}  // namespace ssx
