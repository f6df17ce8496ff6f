// Environment.view(), stop_view() and attach_renderer() (view.hpp).
#include "view.hpp"

#include "convert.hpp"

#include <ssx/class_loader.hpp>
#include <ssx/descriptor.hpp>

#include <cstdint>
#include <string_view>

namespace ssx_python {

namespace {
constexpr const char* kViewer = "viewer";
}

std::string startViewer(ssx::Environment& env, int port, const std::string& bind, double rate_hz, int max_clients) {
  if (env.extension(kViewer) != nullptr) throw py::value_error("ssx: a view is attached already: stop_view() first");
  ssx::Descriptor params(kViewer, {"view()", 0});
  params.set("port", static_cast<std::int64_t>(port))
      .set("bind", bind)
      .set("rate_hz", rate_hz)
      .set("max_clients", static_cast<std::int64_t>(max_clients));
  // an observer: not part of the run's state, so that states saved with and without a view
  // restore into each other; before the first step the environment starts with it (its checks
  // first, then it listens before anything else starts)
  const bool setup = env.state() == ssx::Environment::State::Setup;
  // the viewer says its URL when it listens: taken from its log line
  std::string url;
  env.setLogSink([&url](ssx::LogLevel level, std::string_view message) {
    constexpr std::string_view kSaid = "viewer: http";
    if (message.starts_with(kSaid)) url = message.substr(kSaid.size() - 4);
    toLogging(level, message);
  });
  try {
    env.attachExtension(kViewer, env.classLoader().createExtension(kViewer, kViewer), params);
    if (setup) env.start();
  } catch (...) {
    // refused (a bad rate, a port in use): nothing attached, so that another view() and step() work
    env.setLogSink(toLogging);
    if (env.state() == ssx::Environment::State::Setup) env.removeExtension(kViewer);
    throw;
  }
  env.setLogSink(toLogging);
  return url;
}

void stopViewer(ssx::Environment& env) {
  if (env.extension(kViewer) == nullptr) throw py::value_error("ssx: no view is attached (view() attaches one)");
  env.removeExtension(kViewer);
}

void attachRenderer(ssx::Environment& env, const ssx::RunFiles& files, const FrameRequest& request) {
  ssx::RenderSettings render = env.settings().render;
  if (render.cameras.empty()) {
    ssx::CameraSpec camera;
    camera.frame_scene = true;
    render.cameras.push_back(camera);
  }
  // never over what the run reads or writes
  ssx::RunFiles claimed = files;
  ssx::CameraSpec& first = render.cameras.front();
  auto claim = [&](const std::optional<std::filesystem::path>& path, std::filesystem::path& into, const char* what) {
    if (!path) return;
    const std::string problem = std::string_view(what) == "frames" ? claimed.claimOutputDirectory(*path, what)
                                                                   : claimed.claimOutput(*path, what);
    if (!problem.empty()) throw py::value_error("ssx: attach_renderer: " + problem);
    into = *path;
  };
  claim(request.snapshot, first.snapshot, "snapshot");
  claim(request.video, first.video, "video");
  claim(request.frames, first.frames_dir, "frames");
  if (request.rate_hz) render.rate_hz = *request.rate_hz, render.period_steps = 0;
  if (request.width) render.width = *request.width;
  if (request.height) render.height = *request.height;
  render.engine = request.engine.value_or(render.engine == "null" ? "osmesa" : render.engine);
  render.from = 0;  // from the next step
  render.until = -1;
  env.attachRenderer(std::move(render));
}

}  // namespace ssx_python
