#pragma once
// `ssx inspect` (what a recording holds; a complete copy of one cut short) and `ssx replay` (its
// poses drawn, or its scene re-simulated from a saved state and compared with it).
#include "command_line.hpp"

namespace ssx::cli {

int commandInspect(const InspectArgs& args);
int commandReplay(const ReplayArgs& args);

}  // namespace ssx::cli
