// Values from the library as Python objects (convert.hpp).
#include "convert.hpp"

#include <pybind11/stl.h>

#include <algorithm>
#include <cstdio>

namespace fs = std::filesystem;

namespace ssx_python {

py::array_t<double> vector3(const ssx::Vec3& v) {
  py::array_t<double> a(3);
  auto r = a.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < 3; ++i) r(i) = v[i];
  return a;
}

py::array_t<double> quaternion(const ssx::Quat& q) {
  py::array_t<double> a(4);
  auto r = a.mutable_unchecked<1>();
  r(0) = q.w();
  r(1) = q.x();
  r(2) = q.y();
  r(3) = q.z();
  return a;
}

py::dict flightSummaryDict(const ssx::FlightSummary& s) {
  py::dict d;
  d["robots"] = s.robots;
  d["airborne"] = s.airborne;
  d["landed"] = s.landed;
  d["on_wheels"] = s.on_wheels;
  d["wheeled"] = s.wheeled;
  d["crashed"] = s.crashed;
  d["crashed_names"] = s.crashed_names;
  d["impacts"] = s.impacts;
  d["hardest_impact_mps"] = s.hardest_impact_mps;
  d["hardest_impact_robot"] = s.hardest_impact_robot;
  d["collisions"] = s.collisions;
  d["first_collision_s"] = s.first_collision_s >= 0 ? py::object(py::float_(s.first_collision_s)) : py::object(py::none());
  d["first_collision_pair"] = s.first_collision_pair;
  d["closest_approach_m"] = s.closest_approach_m >= 0 ? py::object(py::float_(s.closest_approach_m)) : py::object(py::none());
  d["closest_pair"] = s.closest_pair;
  d["mean_distance_flown_m"] = s.mean_distance_flown_m;
  d["text"] = s.str();
  return d;
}

py::dict ageDict(const ssx::AgeSummary& s) {
  py::dict d;
  d["count"] = s.count;
  d["median"] = s.median;
  d["p99"] = s.p99;
  d["max"] = s.max;
  return d;
}

py::dict summaryDict(const ssx::TimingSummary& s) {
  py::dict d;
  d["steps"] = s.steps;
  d["timed_steps"] = s.timed_steps;
  d["median_ms"] = s.median_ms;
  d["p95_ms"] = s.p95_ms;
  d["p99_ms"] = s.p99_ms;
  d["max_ms"] = s.max_ms;
  d["mean_ms"] = s.mean_ms;
  d["physics_median_ms"] = s.physics_median_ms;
  d["sensors_median_ms"] = s.sensors_median_ms;
  d["drivers_median_ms"] = s.drivers_median_ms;
  d["render_median_ms"] = s.render_median_ms;
  d["overruns"] = s.overruns;
  d["overruns_long"] = s.overruns_long;
  d["overruns_began_late"] = s.overruns_began_late;
  d["max_lateness_ms"] = s.max_lateness_ms;
  d["wall_s"] = s.wall_s;
  d["simulated_s"] = s.simulated_s;
  d["realtime_factor"] = s.realtime_factor;
  return d;
}


// The library's messages go to Python's logging (logger "ssx"), from whichever thread writes them
// (the GIL is taken for it; a step runs without it). Before Python is up or after it is gone: stderr.
void toLogging(ssx::LogLevel level, std::string_view message) {
  if (Py_IsInitialized() == 0 || _Py_IsFinalizing() != 0) {
    std::fprintf(stderr, "ssx: %.*s\n", static_cast<int>(message.size()), message.data());
    return;
  }
  py::gil_scoped_acquire gil;
  try {
    const char* method = level == ssx::LogLevel::Error ? "error" : level == ssx::LogLevel::Warning ? "warning" : "info";
    py::module_::import("logging").attr("getLogger")("ssx").attr(method)(std::string(message));
  } catch (py::error_already_set& e) {
    e.discard_as_unraisable("ssx logging");
  }
}

namespace {
std::vector<ssx::RecordedBody> startedBodies(const ssx::Environment& env) {
  if (env.state() != ssx::Environment::State::Running)
    throw std::runtime_error("ssx: the run has not started: its bodies are known from the first step on");
  return ssx::recordedBodies(env);
}
}  // namespace

std::vector<std::string> bodyNames(const ssx::Environment& env) {
  std::vector<std::string> out;
  for (const auto& b : startedBodies(env)) out.push_back(b.name);
  return out;
}

py::array_t<double> bodyPoses(const ssx::Environment& env) {
  const std::vector<ssx::RecordedBody> bodies = startedBodies(env);
  py::array_t<double> out({static_cast<py::ssize_t>(bodies.size()), static_cast<py::ssize_t>(7)});
  double* p = out.mutable_data();
  for (const auto& b : bodies) {
    const ssx::Pose pose = b.node->pose();
    const double row[7] = {pose.position.x(), pose.position.y(), pose.position.z(), pose.orientation.w(),
                           pose.orientation.x(), pose.orientation.y(), pose.orientation.z()};
    p = std::copy(row, row + 7, p);
  }
  return out;
}

ssx::SceneOptions sceneOptions(std::optional<std::uint64_t> seed, std::optional<int> threads,
                               const std::vector<fs::path>& plugin_path, const std::optional<std::string>& physics) {
  ssx::SceneOptions o;
  o.seed = seed;
  if (physics) {
    const auto names = ssx::physicEngineNames();
    if (std::find(names.begin(), names.end(), *physics) == names.end())
      throw py::value_error("ssx: unknown physics engine '" + *physics + "' (physics_engines() lists them)");
    o.physics_engine = physics;
  }
  if (threads) {
    if (*threads < 0) throw py::value_error("ssx: threads must be >= 0 (0: one per core), got " + std::to_string(*threads));
    o.threads = threads;
  }
  o.plugin_path = plugin_path;
  return o;
}

}  // namespace ssx_python
