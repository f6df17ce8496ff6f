// Environment.view() (view.hpp).
#include "view.hpp"

#include "convert.hpp"

#include <ssx/class_loader.hpp>
#include <ssx/descriptor.hpp>

#include <cstdint>
#include <string_view>

namespace ssx_python {

std::string startViewer(ssx::Environment& env, int port, const std::string& bind, double rate_hz, int max_clients) {
  ssx::Descriptor params("viewer", {"view()", 0});
  params.set("port", static_cast<std::int64_t>(port))
      .set("bind", bind)
      .set("rate_hz", rate_hz)
      .set("max_clients", static_cast<std::int64_t>(max_clients));
  env.addExtension("viewer", env.classLoader().createExtension("viewer", "viewer"), params);
  // the viewer says its URL when it listens, as the environment starts: taken from its log line
  std::string url;
  env.setLogSink([&url](ssx::LogLevel level, std::string_view message) {
    constexpr std::string_view kSaid = "viewer: http";
    if (message.starts_with(kSaid)) url = message.substr(kSaid.size() - 4);
    toLogging(level, message);
  });
  try {
    env.start();
  } catch (...) {
    // refused (a bad rate, a port in use): the environment as it was, so that another view() and
    // step() work
    env.setLogSink(toLogging);
    if (env.state() == ssx::Environment::State::Setup) env.removeExtension("viewer");
    throw;
  }
  env.setLogSink(toLogging);
  return url;
}

}  // namespace ssx_python
