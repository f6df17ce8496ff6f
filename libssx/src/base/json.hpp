#pragma once
// JSON text, written by hand where a document is a few fields (recordings' channels, commands and
// measurements as JSON rows): numbers as the shortest text that reads back to the same float,
// strings quoted and escaped.

#include <string>
#include <string_view>

namespace ssx::detail {

/// Appends a number as the shortest text that reads back to the same float; `null` when it is not
/// finite (JSON has no NaN or infinity).
void appendNumber(std::string& out, double value);
/// Appends a JSON string (quoted, escaped).
void appendString(std::string& out, std::string_view text);

}  // namespace ssx::detail
