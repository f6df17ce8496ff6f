#pragma once
// XML files to Descriptor trees, every element and attribute with its file and line.

#include <ssx/descriptor.hpp>

#include <filesystem>
#include <string>
#include <string_view>

namespace ssx::detail {

/// Parses `text` (labelled `file` in messages). Throws ConfigError "file:line: error: ..." on
/// a syntax error, with the line of the problem.
Descriptor parseXml(std::string_view text, const std::string& file);

/// Reads and parses a file. Throws ConfigError naming the file when it cannot be read.
Descriptor readXmlFile(const std::filesystem::path& file);

}  // namespace ssx::detail
