// ssx.Recording (recording.hpp).
#include "recording.hpp"

#include "convert.hpp"

#include <ssx/ssx.hpp>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <system_error>

#include <unistd.h>
#include <string>
#include <vector>

namespace py = pybind11;
namespace fs = std::filesystem;

namespace ssx_python {

namespace {

// every sample of a recording, decoded by `decode` (Recording::positions or orientations), as one
// float32 array of times x bodies x Cols
template <int Cols>
py::array_t<float> allSamples(const ssx::Recording& r, std::vector<float> (ssx::Recording::*decode)(std::size_t) const) {
  const auto t = static_cast<py::ssize_t>(r.times().size()), n = static_cast<py::ssize_t>(r.names().size());
  py::array_t<float> out({t, n, static_cast<py::ssize_t>(Cols)});
  float* dst = out.mutable_data();
  py::gil_scoped_release release;
  for (std::size_t k = 0; k < r.times().size(); ++k) {
    const std::vector<float> v = (r.*decode)(k);
    std::copy(v.begin(), v.end(), dst + k * v.size());
  }
  return out;
}

// the state at `t` (seconds): the saved one there, else re-simulated from the one before it in the
// recorded scene, its outputs in a temporary folder removed after; the first before the first
py::tuple snapshot(const ssx::Recording& r, double t, const std::vector<fs::path>& plugin_path) {
  if (!std::isfinite(t)) throw py::value_error("ssx: snapshot(t): t must be finite, got " + std::to_string(t));
  const std::vector<ssx::Nanoseconds> saved = r.stateTimes();
  if (saved.empty()) throw py::value_error("ssx: the recording holds no saved state (recorded with states every 0 s)");
  const ssx::Nanoseconds want = std::max(ssx::toNanoseconds(t), saved.front());
  if (!r.times().empty() && want > r.times().back())
    throw py::value_error("ssx: snapshot(" + std::to_string(t) + "): the recording ends at " +
                          std::to_string(ssx::toSeconds(r.times().back())) + " s");
  ssx::Nanoseconds at = 0;
  std::vector<std::byte> state = r.stateAtOrBefore(want, &at);
  if (at < want) {
    std::error_code ec;
    const fs::path out = fs::temp_directory_path() / ("ssx-snapshot-" + std::to_string(::getpid()) + "-" +
                                                      std::to_string(reinterpret_cast<std::uintptr_t>(&state)));
    ssx::SceneOptions options = sceneOptions(std::nullopt, std::nullopt, plugin_path, std::nullopt);
    options.output_directory = out;
    struct Cleanup {
      fs::path dir;
      ~Cleanup() {
        std::error_code ignored;
        fs::remove_all(dir, ignored);
      }
    } cleanup{out};
    py::gil_scoped_release release;
    ssx::Scene scene = ssx::loadSceneFromString(r.sceneXml(), r.sceneLabel().empty() ? std::string("recorded scene") : r.sceneLabel(),
                                                fs::current_path(), options);
    // (a file the scene names outside the temporary folder, by an absolute path, is the user's)
    for (const fs::path& file : scene.files.outputs()) {
      const fs::path rel = file.lexically_relative(out);
      if (rel.empty() || *rel.begin() == "..")
        throw py::value_error("ssx: snapshot(" + std::to_string(t) + ") re-simulates the recorded scene, which writes " +
                              file.string() + ": it would be written over; take a saved state (state_times) or "
                              "re-simulate with ssx replay --resimulate-from");
    }
    ssx::Environment& env = *scene.environment;
    env.checkState(state);
    fs::create_directories(out, ec);
    env.start();
    env.restoreState(state);
    for (const ssx::PhysicsSwitch& x : r.physicsSwitches())  // (made again at their times)
      if (x.time >= at) env.switchPhysicsAt(x.time, x.to);
    while (env.time() < want) env.step();
    state = env.saveState();
    env.stop();
    at = env.time();
  }
  return py::make_tuple(ssx::toSeconds(at), py::bytes(reinterpret_cast<const char*>(state.data()), state.size()));
}

}  // namespace

void bindRecording(py::module_& m) {
  py::class_<ssx::Recording>(m, "Recording",
                             "A recording (ssx run --record, Environment.record) read back: names, times, every body's "
                             "poses as numpy arrays, the scene, and saved states to continue from.")
      .def(py::init([](const fs::path& file) {
             py::gil_scoped_release release;
             return ssx::Recording(file);
           }),
           py::arg("file"), "Reads a recording; raises RuntimeError naming the file and the byte offset when it is "
                            "not one or is corrupted (a file cut short is read up to its last complete chunk).")
      .def_property_readonly("names", &ssx::Recording::names, "The recorded bodies, in the order of the arrays' rows.")
      .def_property_readonly(
          "times",
          [](const ssx::Recording& r) {
            py::array_t<double> out(static_cast<py::ssize_t>(r.times().size()));
            auto w = out.mutable_unchecked<1>();
            for (std::size_t k = 0; k < r.times().size(); ++k) w(static_cast<py::ssize_t>(k)) = ssx::toSeconds(r.times()[k]);
            return out;
          },
          "Sample times, s (a numpy array).")
      .def("positions", [](const ssx::Recording& r) { return allSamples<3>(r, &ssx::Recording::positions); },
           "Every sample's positions: a float32 array of times x bodies x 3 (m, world frame).")
      .def("orientations", [](const ssx::Recording& r) { return allSamples<4>(r, &ssx::Recording::orientations); },
           "Every sample's orientations: a float32 array of times x bodies x 4 (w, x, y, z; unit quaternions).")
      .def(
          "at",
          [](const ssx::Recording& r, double t) {
            const auto& times = r.times();
            const ssx::Nanoseconds ns = ssx::toNanoseconds(t);
            auto it = std::upper_bound(times.begin(), times.end(), ns);
            if (it == times.begin()) throw py::value_error("ssx: no sample at or before " + std::to_string(t) + " s");
            const auto k = static_cast<std::size_t>(it - times.begin() - 1);
            const auto n = static_cast<py::ssize_t>(r.names().size());
            py::array_t<float> p({n, py::ssize_t{3}}), q({n, py::ssize_t{4}});
            const std::vector<float> pv = r.positions(k), qv = r.orientations(k);
            std::copy(pv.begin(), pv.end(), p.mutable_data());
            std::copy(qv.begin(), qv.end(), q.mutable_data());
            return py::make_tuple(ssx::toSeconds(times[k]), p, q);
          },
          py::arg("t"), "The sample at or before t seconds: (its time, positions bodies x 3, orientations bodies x 4).")
      .def_property_readonly("scene_xml", &ssx::Recording::sceneXml, "The recorded scene as scene XML.")
      .def_property_readonly("scene", &ssx::Recording::sceneLabel, "The scene's file name when it was recorded.")
      .def_property_readonly("version", &ssx::Recording::version, "The ssx version that recorded it.")
      .def_property_readonly("seed", &ssx::Recording::seed, "The recorded run's seed.")
      .def_property_readonly("complete", &ssx::Recording::complete, "False for a file cut short (a killed run).")
      .def_property_readonly("size", &ssx::Recording::size, "Bytes in the file.")
      .def_property_readonly(
          "physics_switches",
          [](const ssx::Recording& r) {
            py::list out;
            for (const ssx::PhysicsSwitch& x : r.physicsSwitches())
              out.append(py::make_tuple(ssx::toSeconds(x.time), x.from, x.to));
            return out;
          },
          "The switches of physics engine made while recording: (time s, from, to) each, in order.")
      .def_property_readonly(
          "state_times",
          [](const ssx::Recording& r) {
            std::vector<double> out;
            for (const ssx::Nanoseconds t : r.stateTimes()) out.push_back(ssx::toSeconds(t));
            return out;
          },
          "Times of the saved states, s.")
      .def(
          "snapshot", &snapshot, py::arg("t"), py::arg("plugin_path") = std::vector<fs::path>{},
          "The state at t seconds: (t, bytes for Environment.restore_state of the recorded scene, e.g. "
          "load_scene_string(recording.scene_xml)). Between two saved states, the recorded scene is re-simulated "
          "from the one before t (its extensions run, their outputs in a temporary folder removed after), as "
          "ssx replay --resimulate-from t does; before the first saved state, the first.")
      .def(
          "channels", [](const ssx::Recording& r) {
            py::dict d;
            for (const auto& [topic, count] : r.channels()) d[py::str(topic)] = count;
            return d;
          },
          "Every channel's topic and message count.")
      .def(
          "channel",
          [](const ssx::Recording& r, const std::string& topic) {
            const auto messages = r.messages(topic);
            const bool json = r.encoding(topic) == "json";
            const py::object loads = py::module_::import("json").attr("loads");
            py::list out;
            for (const auto& [time, data] : messages)
              out.append(py::make_tuple(ssx::toSeconds(time), json ? loads(py::str(data)) : py::object(py::bytes(data))));
            return out;
          },
          py::arg("name"),
          "The messages of channel `name` as a list of (time in s, message): a JSON channel's messages decoded "
          "(dicts), others as bytes. RuntimeError naming the channels there are when there is no such channel.")
      .def("__len__", [](const ssx::Recording& r) { return r.times().size(); })
      .def("__repr__", [](const ssx::Recording& r) {
        return "<ssx.Recording " + r.sceneLabel() + ": " + std::to_string(r.names().size()) + " bodies, " +
               std::to_string(r.times().size()) + " samples>";
      });
}

}  // namespace ssx_python
