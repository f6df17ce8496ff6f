#pragma once
// Validators for the ssx command's numeric options: numbers written as a scene writes them (decimal,
// no hex, no trailing text), checked against their range before CLI11 converts them (its own
// conversion reads hex and clamps integers beyond 64 bits), with the bounds said as a person writes
// them.
#include <ssx/environment.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/random.hpp>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>

namespace ssx::cli {

inline std::string formatBound(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

/// A whole number in decimal from `min` to `max`.
inline CLI::Validator wholeNumber(std::int64_t min, std::int64_t max) {
  const std::string range = std::to_string(min) + " to " + std::to_string(max);
  return CLI::Validator(
      [min, max, range](std::string& text) -> std::string {
        std::int64_t v = 0;
        const char* begin = text.data();
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(begin, end, v);
        const bool digits = !text.empty() && (std::isdigit(static_cast<unsigned char>(text[0])) != 0 || text[0] == '-');
        if (!digits || ptr != end || (ec != std::errc() && ec != std::errc::result_out_of_range))
          return "must be a whole number in decimal from " + range + ", got '" + text + "'";
        if (ec == std::errc::result_out_of_range || v < min || v > max)
          return "must be from " + range + ", got " + text;
        return {};
      },
      "INT in [" + range + "]");
}

/// A seed (ssx::parseSeed: 0 to 2^64 - 1, in decimal).
inline CLI::Validator seedNumber() {
  const std::string range = "0 to " + std::to_string(kMaxSeed);
  return CLI::Validator(
      [range](std::string& text) -> std::string {
        return parseSeed(text) ? std::string() : "must be a whole number in decimal from " + range + ", got '" + text + "'";
      },
      "SEED in [" + range + "]");
}

/// A finite decimal number from `min` to `max` (`open_min`: above min).
inline CLI::Validator realNumber(double min, double max, bool open_min = false) {
  const std::string range = open_min ? "above " + formatBound(min) + " and at most " + formatBound(max)
                                     : "from " + formatBound(min) + " to " + formatBound(max);
  return CLI::Validator(
      [min, max, open_min, range](std::string& text) -> std::string {
        double v = 0;
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, v, std::chars_format::general);
        if (text.empty() || ptr != end || ec != std::errc() || !std::isfinite(v))
          return "must be a decimal number " + range + ", got '" + text + "'";
        if (v < min || v > max || (open_min && v == min)) return "must be " + range + ", got " + text;
        return {};
      },
      "NUMBER " + range);
}

/// A switch of physics engine at a time: `SECONDS:ENGINE` (seconds of simulated time from 0 to
/// kMaxDurationSeconds, an engine of physicEngineNames()); parseSwitch reads it.
inline std::optional<std::pair<double, std::string>> parseSwitch(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) return std::nullopt;
  double v = 0;
  const char* begin = text.data();
  const char* end = begin + colon;
  const auto [ptr, ec] = std::from_chars(begin, end, v, std::chars_format::general);
  if (colon == 0 || ptr != end || ec != std::errc() || !std::isfinite(v) || v < 0 || v > ssx::kMaxDurationSeconds)
    return std::nullopt;
  const std::string engine = text.substr(colon + 1);
  const auto names = ssx::physicEngineNames();
  if (std::find(names.begin(), names.end(), engine) == names.end()) return std::nullopt;
  return std::make_pair(v, engine);
}

/// A switch of physics engine as --switch-physics takes it.
inline CLI::Validator switchSpec() {
  std::string engines;
  for (const auto& n : ssx::physicEngineNames()) engines += (engines.empty() ? "" : ", ") + n;
  return CLI::Validator(
      [engines](std::string& text) -> std::string {
        return parseSwitch(text) ? std::string()
                                 : "must be SECONDS:ENGINE (seconds of simulated time from 0, an engine of " + engines +
                                       "), got '" + text + "'";
      },
      "SECONDS:ENGINE");
}

}  // namespace ssx::cli
