#pragma once
// A plugin library looked at before it is loaded: dlopen maps a file it trusts, and a truncated
// copy (an interrupted install) then kills the process with SIGBUS when the loader touches the
// missing pages. Checked here instead: an ELF shared object for this process's class, byte order
// and machine, whose program headers, loaded segments and section table lie inside the file.
#include <filesystem>
#include <string>

namespace ssx::detail {

/// What is wrong with `file` as a shared library for this process, or an empty string.
std::string sharedLibraryProblem(const std::filesystem::path& file);

}  // namespace ssx::detail
