#pragma once
// Looking at a run from Python while it goes on: the live 3D view in a browser (the viewer
// extension, as `ssx run --view` adds it) and the scene cameras' frames (video, PNG frames, a
// snapshot), each attached between two steps and taken off again without a restart. Neither
// changes the run: what is attached while running is not part of the world's state.
#include <ssx/environment.hpp>
#include <ssx/run_files.hpp>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>

namespace ssx_python {

namespace py = pybind11;

/// Attaches the viewer extension to `env` (started first when still in setup), listening from now
/// on; returns the page's URL. Throws ssx::ConfigError for parameters out of range or a port in
/// use (the environment as it was), ValueError when a viewer is attached already.
std::string startViewer(ssx::Environment& env, int port, const std::string& bind, double rate_hz, int max_clients);
/// Takes the viewer off again (its pages are told the run ended). ValueError when there is none.
void stopViewer(ssx::Environment& env);

/// What attach_renderer takes from Python.
struct FrameRequest {
  std::optional<std::filesystem::path> snapshot, video, frames;
  std::optional<double> rate_hz;
  std::optional<int> width, height;
  std::optional<std::string> engine;
};
/// Environment::attachRenderer with the scene's cameras (the outputs asked for on the first one, a
/// camera framing the scene when it has none); the outputs are checked against `files` (what
/// the run reads and writes) first. ValueError for an output that may not be written.
void attachRenderer(ssx::Environment& env, const ssx::RunFiles& files, const FrameRequest& request);

/// Binds view, stop_view, attach_renderer, detach_renderer and frame_count on the Environment
/// class (`E` has env(), files() and guarded()).
template <class E>
void bindView(py::class_<E>& cls) {
  cls.def(
         "view",
         [](E& e, int port, const std::string& bind, double rate_hz, int max_clients) {
           return e.guarded([&] { return startViewer(e.env(), port, bind, rate_hz, max_clients); });
         },
         py::arg("port") = 8765, py::arg("bind") = "127.0.0.1", py::arg("rate_hz") = 30.0, py::arg("max_clients") = 4,
         "Serves a live 3D view of this environment to web browsers (as ssx run --view) and returns its URL; "
         "port 0 takes a free one. Before the first step it starts the environment; after steps it attaches to the "
         "run as it is. stop_view() takes it off again. The view changes nothing in the run (a page's steering "
         "does, as any command).")
      .def(
          "stop_view", [](E& e) { e.guarded([&] { stopViewer(e.env()); }); },
          "Takes the live view off the run (its pages stop updating); view() can attach one again.")
      .def(
          "attach_renderer",
          [](E& e, std::optional<std::filesystem::path> snapshot, std::optional<std::filesystem::path> video,
             std::optional<std::filesystem::path> frames, std::optional<double> rate_hz, std::optional<int> width,
             std::optional<int> height, std::optional<std::string> engine) {
            const FrameRequest request{std::move(snapshot), std::move(video), std::move(frames), rate_hz, width, height,
                                       std::move(engine)};
            e.guarded([&] { attachRenderer(e.env(), e.files(), request); });
          },
          py::kw_only(), py::arg("snapshot") = py::none(), py::arg("video") = py::none(), py::arg("frames") = py::none(),
          py::arg("rate_hz") = py::none(), py::arg("width") = py::none(), py::arg("height") = py::none(),
          py::arg("engine") = py::none(),
          "Draws the scene cameras' frames from the next step on (a camera framing the scene when it has none): "
          "snapshot=PNG of the last frame, video=MP4 (needs ffmpeg), frames=a directory of PNG files, for the first "
          "camera; rate_hz frames per simulated second (default: the scene's, else 25); width and height in pixels; "
          "engine (default osmesa). Frames being drawn are finished first. Changes nothing in the run.")
      .def(
          "detach_renderer", [](E& e) { e.guarded([&] { e.env().detachRenderer(); }); },
          "Stops drawing frames: the outputs finished (a video closed, the snapshot written).")
      .def_property_readonly(
          "frame_count", [](E& e) { return e.guarded([&] { return e.env().frameCount(); }); },
          "Frames drawn for the scene's cameras so far.");
}

}  // namespace ssx_python
