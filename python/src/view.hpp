#pragma once
// Environment.view(): the live 3D view in a browser (the viewer extension, as `ssx run --view`
// adds it), started with the environment.
#include <ssx/environment.hpp>

#include <string>

namespace ssx_python {

/// Adds the viewer extension to `env` (still in setup) with these parameters and starts the
/// environment, so that it listens from now on; returns the page's URL. Throws ssx::ConfigError for
/// parameters out of range or a port in use.
std::string startViewer(ssx::Environment& env, int port, const std::string& bind, double rate_hz, int max_clients);

}  // namespace ssx_python
