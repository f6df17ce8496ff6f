// ssx.Recording (recording.hpp).
#include "recording.hpp"

#include <ssx/ssx.hpp>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
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
          "state_times",
          [](const ssx::Recording& r) {
            std::vector<double> out;
            for (const ssx::Nanoseconds t : r.stateTimes()) out.push_back(ssx::toSeconds(t));
            return out;
          },
          "Times of the saved states, s.")
      .def(
          "snapshot",
          [](const ssx::Recording& r, double t) {
            ssx::Nanoseconds at = 0;
            const std::vector<std::byte> s = r.stateAtOrBefore(ssx::toNanoseconds(t), &at);
            return py::make_tuple(ssx::toSeconds(at), py::bytes(reinterpret_cast<const char*>(s.data()), s.size()));
          },
          py::arg("t"),
          "The saved state at or before t seconds: (its time, bytes for Environment.restore_state of the recorded "
          "scene, e.g. load_scene_string(recording.scene_xml)).")
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
