#include <ssx/error.hpp>

namespace ssx {

std::string SourceLocation::str() const {
  if (file.empty()) return "<code>";
  if (line <= 0) return file;
  return file + ":" + std::to_string(line);
}

ConfigError::ConfigError(SourceLocation where, const std::string& message)
    : Error(where.str() + ": error: " + message), where_(std::move(where)), detail_(message) {}

StepError::StepError(std::string artifact, std::string plugin, std::int64_t step, const std::string& what)
    : Error("step " + std::to_string(step) + ": artifact '" + artifact + "', " + plugin + ": " + what),
      artifact_(std::move(artifact)),
      plugin_(std::move(plugin)),
      step_(step) {}

}  // namespace ssx
