#pragma once
// Between Python and the library: values as Python objects (vectors, quaternions and counts as
// numpy arrays, timing summaries as dicts), scene options from Python's arguments, and the
// library's messages to Python's logging.
#include <ssx/ssx.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace ssx_python {

namespace py = pybind11;

// Marks an environment as in use for the length of one call.
class InUse {
 public:
  explicit InUse(std::atomic<bool>& flag) : flag_(flag) {
    if (flag_.exchange(true))
      throw std::runtime_error("ssx: this Environment is in use by another thread (stepping or running); "
                               "an environment is used from one thread at a time");
  }
  InUse(const InUse&) = delete;
  InUse& operator=(const InUse&) = delete;
  ~InUse() { flag_.store(false); }

 private:
  std::atomic<bool>& flag_;
};

/// x, y, z as a float64 array of 3.
py::array_t<double> vector3(const ssx::Vec3& v);
/// w, x, y, z as a float64 array of 4.
py::array_t<double> quaternion(const ssx::Quat& q);
/// Integer counts (an IMU's) as an int32 array.
template <std::size_t N>
py::array_t<std::int32_t> counts(const std::array<std::int32_t, N>& c) {
  py::array_t<std::int32_t> a(static_cast<py::ssize_t>(N));
  auto r = a.mutable_unchecked<1>();
  for (std::size_t i = 0; i < N; ++i) r(static_cast<py::ssize_t>(i)) = c[i];
  return a;
}
/// Every moving body as recordings and the viewer list them (ssx::recordedBodies): names, and
/// poses as N x 7 (x, y, z, qw, qx, qy, qz); RuntimeError before the first step.
std::vector<std::string> bodyNames(const ssx::Environment& env);
py::array_t<double> bodyPoses(const ssx::Environment& env);
/// What happened to the robots (FlightRecorder) as a dict of its fields, with 'text'.
py::dict flightSummaryDict(const ssx::FlightSummary& s);
/// The ghosts' pose ages as a dict: count, median, p99, max.
py::dict ageDict(const ssx::AgeSummary& s);
/// A run's timing summary as a dict of its fields.
py::dict summaryDict(const ssx::TimingSummary& s);
/// load_scene's arguments as SceneOptions (ValueError for an unknown engine or negative threads).
ssx::SceneOptions sceneOptions(std::optional<std::uint64_t> seed, std::optional<int> threads,
                               const std::vector<std::filesystem::path>& plugin_path,
                               const std::optional<std::string>& physics);
/// A log sink (Environment::setLogSink) writing to Python's logger "ssx".
void toLogging(ssx::LogLevel level, std::string_view message);

}  // namespace ssx_python
