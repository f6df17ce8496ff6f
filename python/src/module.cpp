// The Python module `ssx._ssx` (imported as `ssx`): scenes, stepping, state as numpy arrays,
// set-points, measurements, save and restore. See python/ssx/__init__.py and docs/python.md.
//
// Threads: every call comes in holding the GIL; stepping and running release it. An environment
// is used by one thread at a time (as in C++): a call made while another thread is stepping the
// same environment raises RuntimeError instead of racing it.
#include "commands.hpp"
#include "convert.hpp"
#include "ghosts.hpp"
#include "joints.hpp"
#include "learn.hpp"
#include "physics.hpp"
#include "recording.hpp"
#include "view.hpp"

#include <ssx/ssx.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace py = pybind11;
namespace fs = std::filesystem;

namespace {

using ssx_python::Array;
using ssx_python::counts;
using ssx_python::InUse;
using ssx_python::quaternion;
using ssx_python::sceneOptions;
using ssx_python::summaryDict;
using ssx_python::toLogging;
using ssx_python::vector3;

class PyEnvironment {
 public:
  explicit PyEnvironment(ssx::Scene scene) : scene_(std::move(scene)), env_(*scene_.environment), targets_(env_) {
    for (const ssx::Artifact* a : std::as_const(env_).selectArtifacts("*")) dynamic_.push_back(a);
    env_.setLogSink(toLogging);
    // what loading had to say (unknown attributes and the like), as warnings of the same logger
    for (const auto& w : scene_.warnings) toLogging(ssx::LogLevel::Warning, w.str());
  }

  ssx::Environment& env() { return env_; }
  const ssx::RunFiles& files() const { return scene_.files; }
  // `read()` while no other thread steps this environment (RuntimeError otherwise)
  template <class Read>
  auto guarded(Read read) {
    InUse use(busy_);
    return read();
  }

  void step(std::int64_t n) {
    if (n < 0) throw py::value_error("ssx: step(n) needs n >= 0, got " + std::to_string(n));
    InUse use(busy_);
    // in slices, between which Ctrl-C (a pending signal) stops it: the steps are the same either way
    constexpr std::int64_t kSlice = 256;
    for (std::int64_t done = 0; done < n;) {
      const std::int64_t k = std::min(kSlice, n - done);
      {
        py::gil_scoped_release release;
        // the flight summary looks every 10th step, as ssx run's does (looking changes no bit)
        for (std::int64_t left = k; left > 0;) {
          const std::int64_t to_tenth = 10 - env_.stepCount() % 10;
          const std::int64_t now = std::min(left, to_tenth);
          env_.step(now);
          left -= now;
          if (env_.stepCount() % 10 == 0) flights_.observe(env_);
        }
      }
      done += k;
      if (done < n && PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  double time() const {
    InUse use(busy_);
    return ssx::toSeconds(env_.time());
  }
  double timestep() const { return ssx::toSeconds(env_.timestep()); }
  std::optional<double> duration() const {
    if (!scene_.duration) return std::nullopt;
    return ssx::toSeconds(*scene_.duration);
  }

  std::vector<std::string> artifactNames() const {
    InUse use(busy_);
    std::vector<std::string> names;
    names.reserve(env_.artifactCount());
    for (std::size_t i = 0; i < env_.artifactCount(); ++i) names.push_back(std::as_const(env_).artifact(i).name());
    return names;
  }
  // what happened to the robots so far (FlightRecorder, every 10th step), as a dict
  py::dict flightSummary() {
    InUse use(busy_);
    ssx::FlightRecorder now = flights_;
    if (env_.state() == ssx::Environment::State::Running) now.observe(env_);  // the end states as of now
    return ssx_python::flightSummaryDict(now.summary());
  }
  // every metric the plugins publish now (ssx::MetricSource), by artifact: {name: {metric: value}}
  py::dict metrics() {
    InUse use(busy_);
    py::dict out;
    std::vector<ssx::Metric> values;
    auto add = [&](const std::string& name, const ssx::MetricSource* source) {
      if (source == nullptr) return;
      values.clear();
      source->metrics(values);
      if (values.empty()) return;
      py::dict m;
      for (const auto& v : values) m[py::str(v.name)] = v.value;
      out[py::str(name)] = m;
    };
    for (std::size_t i = 0; i < env_.artifactCount(); ++i) {
      const ssx::Artifact& a = std::as_const(env_).artifact(i);
      add(a.name(), dynamic_cast<const ssx::MetricSource*>(a.driver()));
    }
    // (extension names are scene-unique, as artifact names)
    for (const auto& name : env_.extensionNames()) add(name, dynamic_cast<const ssx::MetricSource*>(env_.extension(name)));
    return out;
  }
  // contact points the physics engine found in the last step
  std::size_t contacts() {
    InUse use(busy_);
    return env_.state() == ssx::Environment::State::Running ? env_.physics().contactCount() : 0;
  }

  // (fixed from loading on, as setpointNames, timestep, duration and seed: readable at any time)
  std::vector<std::string> dynamicNames() const {
    std::vector<std::string> names;
    names.reserve(dynamic_.size());
    for (const ssx::Artifact* a : dynamic_) names.push_back(a->name());
    return names;
  }
  std::vector<std::string> setpointNames() const { return targets_.names(); }

  // N x 3 (or N x 4) of every dynamic artifact's first root, from the published snapshot
  template <int Cols, class Fill>
  py::array_t<double> rows(Fill fill) {
    InUse use(busy_);
    py::array_t<double> out({static_cast<py::ssize_t>(dynamic_.size()), static_cast<py::ssize_t>(Cols)});
    double* p = out.mutable_data();
    for (const ssx::Artifact* a : dynamic_) {
      fill(a->root(), p);
      p += Cols;
    }
    return out;
  }
  py::array_t<double> positions() {
    return rows<3>([](const ssx::PhysicNode& n, double* p) {
      const ssx::Vec3 v = n.pose().position;
      p[0] = v.x(), p[1] = v.y(), p[2] = v.z();
    });
  }
  py::array_t<double> orientations() {
    return rows<4>([](const ssx::PhysicNode& n, double* p) {
      const ssx::Quat q = n.pose().orientation;
      p[0] = q.w(), p[1] = q.x(), p[2] = q.y(), p[3] = q.z();
    });
  }
  py::array_t<double> linearVelocities() {
    return rows<3>([](const ssx::PhysicNode& n, double* p) {
      const ssx::Vec3 v = n.state().linear_velocity;
      p[0] = v.x(), p[1] = v.y(), p[2] = v.z();
    });
  }
  py::array_t<double> angularVelocities() {
    return rows<3>([](const ssx::PhysicNode& n, double* p) {
      const ssx::Vec3 v = n.state().angular_velocity;
      p[0] = v.x(), p[1] = v.y(), p[2] = v.z();
    });
  }

  void setSetpoints(const py::handle& positions, const py::handle& velocities, const py::handle& yaws,
                    const py::handle& accelerations, const py::handle& yaw_rates, const py::handle& robots) {
    InUse use(busy_);
    if (env_.state() == ssx::Environment::State::Setup) env_.start();
    targets_.setSetpoints(positions, velocities, yaws, accelerations, yaw_rates, robots);
  }

  void setCommands(const std::string& level, const py::handle& values, const py::handle& robots) {
    InUse use(busy_);
    if (env_.state() == ssx::Environment::State::Setup) env_.start();
    targets_.setCommands(level, values, robots);
  }

  // the latest measurement of type M of an artifact's sensors: the first such sensor, or sensor `index`
  template <class M>
  const M& measurement(const std::string& artifact, std::optional<std::size_t> index, const char* kind) {
    const ssx::Artifact* a = std::as_const(env_).findArtifact(artifact);
    if (a == nullptr) throw py::key_error("ssx: no artifact named '" + artifact + "'");
    if (index) {
      if (*index >= a->sensorCount())
        throw py::index_error("ssx: artifact '" + artifact + "' has " + std::to_string(a->sensorCount()) +
                              " sensor(s), no sensor " + std::to_string(*index));
      if (const auto* m = dynamic_cast<const M*>(&a->sensor(*index).latest())) return *m;
      throw py::value_error("ssx: sensor " + std::to_string(*index) + " of artifact '" + artifact + "' (" +
                            a->sensor(*index).className() + ") does not measure " + kind);
    }
    for (std::size_t i = 0; i < a->sensorCount(); ++i)
      if (const auto* m = dynamic_cast<const M*>(&a->sensor(i).latest())) return *m;
    throw py::value_error("ssx: artifact '" + artifact + "' has no " + kind + " sensor");
  }

  py::dict imu(const std::string& artifact, std::optional<std::size_t> index) {
    InUse use(busy_);
    const auto& m = measurement<ssx::ImuMeasurement>(artifact, index, "imu");
    py::dict d;
    d["stamp"] = ssx::toSeconds(m.stamp);
    d["accelerometer"] = vector3(m.accelerometer);
    d["gyroscope"] = vector3(m.gyroscope);
    d["accelerometer_counts"] = counts(m.accelerometer_counts);
    d["gyroscope_counts"] = counts(m.gyroscope_counts);
    d["accelerometer_lsb"] = m.accelerometer_lsb;
    d["gyroscope_lsb"] = m.gyroscope_lsb;
    return d;
  }

  py::dict pose(const std::string& artifact, std::optional<std::size_t> index) {
    InUse use(busy_);
    const auto& m = measurement<ssx::PoseMeasurement>(artifact, index, "pose");
    py::dict d;
    d["stamp"] = ssx::toSeconds(m.stamp);
    d["position"] = vector3(m.pose.position);
    d["orientation"] = quaternion(m.pose.orientation);
    d["linear_velocity"] = vector3(m.linear_velocity);
    d["angular_velocity"] = vector3(m.angular_velocity);
    return d;
  }

  py::dict range(const std::string& artifact, std::optional<std::size_t> index) {
    InUse use(busy_);
    const auto& m = measurement<ssx::RangeMeasurement>(artifact, index, "range");
    const auto n = static_cast<py::ssize_t>(m.detections.size());
    py::array_t<double> relative({n, py::ssize_t{3}});
    py::array_t<double> distance(n);
    py::array_t<std::int64_t> seen(n);
    py::array_t<bool> obstacle(n);
    auto rel = relative.mutable_unchecked<2>();
    auto dist = distance.mutable_unchecked<1>();
    auto idx = seen.mutable_unchecked<1>();
    auto obs = obstacle.mutable_unchecked<1>();
    for (py::ssize_t i = 0; i < n; ++i) {
      const auto& det = m.detections[static_cast<std::size_t>(i)];
      for (py::ssize_t k = 0; k < 3; ++k) rel(i, k) = det.relative[k];
      dist(i) = det.distance;
      idx(i) = static_cast<std::int64_t>(det.artifact);
      obs(i) = det.obstacle;
    }
    py::dict d;
    d["stamp"] = ssx::toSeconds(m.stamp);
    d["body_frame"] = m.body_frame;
    d["relative"] = relative;
    d["distance"] = distance;
    d["artifact"] = seen;
    d["obstacle"] = obstacle;
    return d;
  }

  py::bytes saveState() {
    InUse use(busy_);
    std::vector<std::byte> state;
    {
      py::gil_scoped_release release;
      if (env_.state() == ssx::Environment::State::Setup) env_.start();
      state = env_.saveState();
    }
    return {reinterpret_cast<const char*>(state.data()), state.size()};
  }

  void restoreState(const py::bytes& state) {
    InUse use(busy_);
    const std::string_view view = state;
    const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(view.data()), view.size());
    py::gil_scoped_release release;
    env_.restoreState(bytes);
  }

  // Paces steps for `seconds` of simulated time (the scene's duration when None). Ctrl-C (any
  // Python signal handler that raises) ends the run between two steps and raises here; the
  // environment stays usable.
  py::dict run(std::optional<double> seconds, bool realtime, std::optional<double> realtime_factor,
               std::optional<int> realtime_priority, std::optional<fs::path> record) {
    if (record) {
      // this run recorded: samples dropped rather than a paced step held up
      this->record(*record, 25.0, 10.0, realtime, std::nullopt, false, false, false);
      py::dict out;
      try {
        out = run(seconds, realtime, realtime_factor, realtime_priority, std::nullopt);
      } catch (...) {
        if (recorder_) {
          std::unique_ptr<ssx::Recorder> recorder = std::move(recorder_);
          try {
            recorder->finish();
          } catch (...) {
          }
        }
        throw;
      }
      out["recording"] = stopRecording();
      return out;
    }
    InUse use(busy_);
    ssx::RunOptions run = scene_.run;
    run.mode = realtime ? ssx::RunOptions::Mode::RealTime : ssx::RunOptions::Mode::Fast;
    if (realtime_priority) {
      // refused before a step: out of range, or not permitted to this process
      if (const std::string problem = ssx::realtimePriorityProblem(*realtime_priority); !problem.empty())
        throw py::value_error("ssx: realtime_priority " + std::to_string(*realtime_priority) + ": " + problem);
      run.realtime_priority = *realtime_priority;
    }
    if (realtime_factor) {
      if (!(*realtime_factor >= ssx::kMinRealtimeFactor && *realtime_factor <= ssx::kMaxRealtimeFactor))
        throw py::value_error("ssx: realtime_factor must be in [1e-3, 1e6], got " + std::to_string(*realtime_factor));
      run.realtime_factor = *realtime_factor;
    }
    ssx::Nanoseconds duration = 0;
    if (seconds) {
      if (!(*seconds >= 0.0 && *seconds <= ssx::kMaxDurationSeconds))
        throw py::value_error("ssx: run(seconds) needs 0 <= seconds <= 1e9, got " + std::to_string(*seconds));
      duration = ssx::toNanoseconds(*seconds);
    } else if (scene_.duration) {
      duration = *scene_.duration;
    } else {
      throw py::value_error("ssx: run() needs seconds: the scene gives no <environment duration>");
    }
    run.steps = (duration + env_.timestep() - 1) / env_.timestep();
    std::atomic<bool> stop{false};
    run.stop = &stop;
    bool interrupted = false;
    // Python's signal handlers run only when Python code runs: ask for them every 50 ms of wall time
    auto last_check = std::chrono::steady_clock::now();
    run.on_step = [&](const ssx::Environment&) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_check < std::chrono::milliseconds(50)) return;
      last_check = now;
      py::gil_scoped_acquire acquire;
      if (PyErr_CheckSignals() != 0) {
        interrupted = true;
        stop.store(true);
      }
    };
    ssx::TimingSummary summary;
    {
      py::gil_scoped_release release;
      summary = env_.run(run);
    }
    if (interrupted) throw py::error_already_set();
    return summaryDict(summary);
  }

  // records from the next step on, whether stepped or run, until stop_recording() or close()
  void record(const fs::path& file, double rate_hz, double state_every_s, bool drop_when_behind,
              std::optional<bool> foxglove, bool timing, bool sensors, bool commands) {
    InUse use(busy_);
    if (recorder_) throw py::value_error("ssx: already recording to " + recording_file_.string() + ": stop_recording() first");
    ssx::RecordOptions o;
    o.file = file;
    o.rate_hz = rate_hz;
    o.state_every_s = state_every_s;
    o.drop_when_behind = drop_when_behind;
    o.foxglove = foxglove, o.timing = timing, o.sensors = sensors, o.commands = commands;
    o.scene_xml = scene_.model ? scene_.model->toXml() : std::string();
    o.scene_label = scene_.file.filename().string();
    // never over what the scene reads or writes
    ssx::RunFiles files = scene_.files;
    if (const std::string problem = files.claimOutput(file, "record", true); !problem.empty())
      throw py::value_error("ssx: " + problem);
    recorder_ = std::make_unique<ssx::Recorder>(env_, std::move(o));
    recording_file_ = file;
  }

  py::dict stopRecording() {
    InUse use(busy_);
    if (!recorder_) throw py::value_error("ssx: not recording");
    std::unique_ptr<ssx::Recorder> recorder = std::move(recorder_);
    ssx::RecordSummary s;
    {
      py::gil_scoped_release release;
      s = recorder->finish();
    }
    py::dict d;
    d["file"] = recording_file_;
    d["samples"] = s.samples;
    d["dropped"] = s.dropped;
    d["states"] = s.states;
    d["bodies"] = s.bodies;
    d["bytes"] = s.bytes;
    d["text"] = s.str(recording_file_);
    return d;
  }
  bool recording() const { return recorder_ != nullptr; }

  void close() {
    InUse use(busy_);
    py::gil_scoped_release release;
    if (recorder_) {
      std::unique_ptr<ssx::Recorder> recorder = std::move(recorder_);
      recorder->finish();
    }
    if (env_.state() == ssx::Environment::State::Running) env_.stop();
  }

  // (never raises: a debugger or a log shows it while another thread steps)
  std::string repr() const {
    std::string t = "stepping in another thread";
    if (!busy_.exchange(true)) {
      t = "t = " + std::to_string(ssx::toSeconds(env_.time())) + " s";
      busy_.store(false);
    }
    return "<ssx.Environment " + scene_.file.string() + ": " + std::to_string(env_.artifactCount()) + " artifacts, " +
           t + ">";
  }

 private:
  ssx::Scene scene_;
  ssx::Environment& env_;
  std::vector<const ssx::Artifact*> dynamic_;
  ssx_python::CommandTargets targets_;
  mutable std::atomic<bool> busy_{false};  // (reads guard it too: InUse)
  ssx::FlightRecorder flights_;
  std::unique_ptr<ssx::Recorder> recorder_;
  fs::path recording_file_;
};

}  // namespace

PYBIND11_MODULE(_ssx, m) {
  m.doc() = "ssx: real-time simulation of robot swarms in 3D";
  m.attr("__version__") = SSX_VERSION_STRING;

  static py::exception<ssx::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<ssx::SceneError> scene_error(m, "SceneError", error.ptr());
  static py::exception<ssx::StepError> step_error(m, "StepError", error.ptr());
  static py::exception<ssx::StateError> state_error(m, "StateError", error.ptr());
  static py::exception<ssx::ConfigError> config_error(m, "ConfigError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ssx::SceneError& e) {
      scene_error(e.what());
    } catch (const ssx::StepError& e) {
      step_error(e.what());
    } catch (const ssx::StateError& e) {
      state_error(e.what());
    } catch (const ssx::ConfigError& e) {
      config_error(e.what());
    } catch (const ssx::Error& e) {
      error(e.what());
    }
  });

  py::class_<PyEnvironment> environment(m, "Environment",
                            "A loaded scene: step it, read its state as numpy arrays, command it. Made by "
                            "load_scene or load_scene_string.");
  environment
      .def("step", &PyEnvironment::step, py::arg("n") = 1,
           "Advances n timesteps (starting the environment first if needed). Releases the GIL.")
      .def_property_readonly("time", &PyEnvironment::time, "Simulated time, s.")
      .def_property_readonly("time_ns", [](PyEnvironment& e) { return e.guarded([&] { return e.env().time(); }); },
                             "Simulated time, ns.")
      .def_property_readonly("timestep", &PyEnvironment::timestep, "Physics timestep, s.")
      .def_property_readonly("step_count", [](PyEnvironment& e) { return e.guarded([&] { return e.env().stepCount(); }); })
      .def_property_readonly("duration", &PyEnvironment::duration, "<environment duration> in s, or None.")
      .def_property_readonly("seed", [](PyEnvironment& e) { return e.env().settings().seed; })
      .def_property_readonly("threads", [](PyEnvironment& e) { return e.guarded([&] { return e.env().threadCount(); }); },
                             "Worker threads of the parallel phases (known once started).")
      .def("artifact_names", &PyEnvironment::artifactNames, "Every artifact, in artifact order.")
      .def("dynamic_names", &PyEnvironment::dynamicNames,
           "The artifacts with a dynamic root: the rows of positions() and the other state arrays.")
      .def("setpoint_names", &PyEnvironment::setpointNames,
           "The artifacts whose driver follows set-points: the rows of set_setpoints().")
      .def("state_hash", [](PyEnvironment& e) { return e.guarded([&] { return e.env().stateHash(); }); },
           "64-bit hash of every body's pose and velocities, bit for bit, and the time.")
      .def("body_names", [](PyEnvironment& e) { return e.guarded([&] { return ssx_python::bodyNames(e.env()); }); },
           "Every moving body, as recordings and the viewer list them: each dynamic artifact's first root "
           "named as the artifact, then its other bodies as 'artifact/node' (static-rooted arms and doors too).")
      .def("body_poses", [](PyEnvironment& e) { return e.guarded([&] { return ssx_python::bodyPoses(e.env()); }); },
           "N x 7 poses of body_names() (x, y, z in m; qw, qx, qy, qz), world frame.")
      .def("positions", &PyEnvironment::positions, "N x 3 positions (m, world) of the dynamic artifacts' first roots.")
      .def("orientations", &PyEnvironment::orientations, "N x 4 orientations as quaternions (w, x, y, z).")
      .def("linear_velocities", &PyEnvironment::linearVelocities, "N x 3, m/s, world frame.")
      .def("angular_velocities", &PyEnvironment::angularVelocities, "N x 3, rad/s, world frame.")
      .def("set_setpoints", &PyEnvironment::setSetpoints, py::arg("positions"), py::arg("velocities") = py::none(),
           py::arg("yaws") = py::none(), py::arg("accelerations") = py::none(), py::arg("yaw_rates") = py::none(),
           py::arg("robots") = py::none(),
           "One row per robot (setpoint_names(), or the names or indices in `robots`): positions N x 3 (m), "
           "velocities N x 3 (m/s, feed-forward), accelerations N x 3 (m/s^2, feed-forward), yaws N (rad), "
           "yaw_rates N (rad/s, feed-forward). Held until the next call. Every row is checked before any robot "
           "gets one.")
      .def("set_commands", &PyEnvironment::setCommands, py::arg("level"), py::arg("values"),
           py::arg("robots") = py::none(),
           "Commands at a level, one row per robot (setpoint_names(), or the names or indices in `robots`): "
           "'position' x, y, z, yaw [, vx, vy, vz [, ax, ay, az [, yaw_rate]]]; 'velocity' vx, vy, vz, yaw_rate; "
           "'attitude' roll, pitch (rad), yaw_rate (rad/s), thrust (N); 'rates' p, q, r (rad/s), thrust (N); "
           "'rotors' one speed per rotor (rad/s); 'wheels' left, right wheel speed (rad/s). Held until the next command. "
           "Every row is checked (shape, NaN, "
           "levels and values the robot takes) before any robot gets one.")
      .def("imu", &PyEnvironment::imu, py::arg("artifact"), py::arg("sensor") = py::none(),
           "The latest IMU measurement of an artifact (its first IMU, or sensor index `sensor`), as a dict.")
      .def("pose", &PyEnvironment::pose, py::arg("artifact"), py::arg("sensor") = py::none(),
           "The latest pose measurement of an artifact, as a dict.")
      .def("range", &PyEnvironment::range, py::arg("artifact"), py::arg("sensor") = py::none(),
           "The latest range measurement of an artifact: detections as arrays, nearest first.")
      .def("flight_summary", &PyEnvironment::flightSummary,
           "What happened to the robots so far (every 10th step): airborne, landed, on wheels, crashed, impacts, collisions between "
           "robots (count, first time and pair), closest approach, mean distance flown; 'text' says it in a line.")
      .def("metrics", &PyEnvironment::metrics,
           "Every metric the drivers and extensions publish now (ssx::MetricSource, e.g. the formation's formation_error), as "
           "{artifact or extension: {metric: value}}.")
      .def("contacts", &PyEnvironment::contacts, "Contact points the physics engine found in the last step.")
      .def("save_state", &PyEnvironment::saveState, "Everything that determines the future, as bytes.")
      .def("restore_state", &PyEnvironment::restoreState, py::arg("state"),
           "Continues from save_state() bytes: the next steps are bitwise those of the saving run.")
      .def("run", &PyEnvironment::run, py::arg("seconds") = py::none(), py::arg("realtime") = true,
           py::arg("realtime_factor") = py::none(), py::arg("realtime_priority") = py::none(),
           py::arg("record") = py::none(),
           "Runs `seconds` of simulated time (default: the scene's duration), paced to the wall clock "
           "unless realtime=False; returns the timing summary. Ctrl-C stops it between two steps. "
           "realtime_priority (1-99) steps at that SCHED_FIFO priority (needs root or CAP_SYS_NICE). record=FILE "
           "records the run (as record() does; samples dropped rather than a paced step held up), its summary under "
           "'recording'.")
      .def("record", &PyEnvironment::record, py::arg("file"), py::arg("rate_hz") = 25.0, py::arg("state_every_s") = 10.0,
           py::arg("drop_when_behind") = false, py::arg("foxglove") = py::none(), py::arg("timing") = false,
           py::arg("sensors") = false, py::arg("commands") = false,
           "Records the run from the next step on (stepped or run) into an MCAP file: the scene, every body's pose "
           "at rate_hz, a saved state every state_every_s; read it back with ssx.Recording. Written by a thread of "
           "its own; drop_when_behind drops samples rather than wait for it. foxglove: /tf and /scene for Foxglove "
           "(None: for up to 1,000 bodies); timing: /ssx/timing; sensors: /ssx/sensors; commands: /ssx/commands.")
      .def("stop_recording", &PyEnvironment::stopRecording,
           "Ends the recording (the file complete) and returns what it wrote: samples, dropped, states, bytes.")
      .def_property_readonly("recording", &PyEnvironment::recording, "Whether a recording is running.")
      .def("close", &PyEnvironment::close,
           "Stops the environment: a recording finished, plugins destroyed, files and videos finished.")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](PyEnvironment& e, const py::args&) { e.close(); })
      .def("__repr__", &PyEnvironment::repr);

  ssx_python::bindGhostsAndOperators(environment);
  ssx_python::bindJoints(environment);
  ssx_python::bindPhysics(environment);
  ssx_python::bindView(environment);
  ssx_python::bindRecording(m);
  ssx_python::bindLearn(m, environment);

  m.def(
      "load_scene",
      [](const fs::path& path, std::optional<std::uint64_t> seed, std::optional<int> threads,
         const std::vector<fs::path>& plugin_path, const std::optional<std::string>& physics) {
        ssx::SceneOptions options = sceneOptions(seed, threads, plugin_path, physics);
        std::optional<ssx::Scene> scene;
        {
          py::gil_scoped_release release;
          scene.emplace(ssx::loadScene(path, options));
        }
        return std::make_unique<PyEnvironment>(std::move(*scene));
      },
      py::arg("path"), py::arg("seed") = py::none(), py::arg("threads") = py::none(),
      py::arg("plugin_path") = std::vector<fs::path>{}, py::arg("physics") = py::none(),
      "Loads a scene file (physics: an engine name overriding the scene's). Raises SceneError (its text: every `file:line: error:` line) before anything starts.");
  m.def(
      "load_scene_string",
      [](const std::string& xml, const fs::path& base_dir, std::optional<std::uint64_t> seed,
         std::optional<int> threads, const std::string& label, const std::vector<fs::path>& plugin_path,
         const std::optional<std::string>& physics) {
        ssx::SceneOptions options = sceneOptions(seed, threads, plugin_path, physics);
        std::optional<ssx::Scene> scene;
        {
          py::gil_scoped_release release;
          scene.emplace(ssx::loadSceneFromString(xml, label, base_dir, options));
        }
        return std::make_unique<PyEnvironment>(std::move(*scene));
      },
      py::arg("xml"), py::arg("base_dir") = fs::path("."), py::arg("seed") = py::none(),
      py::arg("threads") = py::none(), py::arg("label") = "<string>",
      py::arg("plugin_path") = std::vector<fs::path>{}, py::arg("physics") = py::none(),
      "Loads a scene from text; relative files resolve against base_dir, messages name `label`.");
  m.def("physics_engines", &ssx::physicEngineNames, "The physics engines of this build (\"ode\", \"bullet\").");
  m.def("data_directory", &ssx::installedDataDirectory,
        "The installed artifact types (artifacts/) and example scenes (scenes/).");
}
