// ssx._ssx.VectorEnvironment (learn.hpp).
#include "learn.hpp"

#include "convert.hpp"

#include <ssx/scene_model.hpp>
#include <ssx/ssx.hpp>
#include <ssx/vector_environment.hpp>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ssx_python {

namespace {

namespace py = pybind11;
namespace fs = std::filesystem;
using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
constexpr std::size_t kTimingSamples = 0;  // none: no clock read in a copy's step

// a ConfigError as Python's ValueError says it: "ssx: file:line: error: ..." for bad input of a
// file, "ssx: ..." for arguments given in code (no "<code>: error:" before them)
std::string configMessage(const ssx::ConfigError& e) {
  return std::string("ssx: ") + (e.where().file.empty() ? e.detail() : std::string(e.what()));
}

class PyVectorEnvironment {
 public:
  PyVectorEnvironment(const std::string& xml, std::size_t count, const fs::path& base_dir,
                      std::optional<std::uint64_t> seed, std::optional<int> threads, const std::string& label,
                      const std::vector<fs::path>& plugin_path, const std::optional<std::string>& physics) {
    if (count == 0) throw py::value_error("ssx: a VectorEnvironment needs num_envs >= 1");
    if (threads && *threads < 0) throw py::value_error("ssx: threads must be >= 0 (0: one per core)");
    const ssx::SceneOptions options = sceneOptions(seed, 1, plugin_path, physics);
    py::gil_scoped_release release;
    // read once, built num_envs times; the copies keep no timing (no clock read in their steps;
    // the default ring, 16 MiB a copy, would be 16 GiB for a thousand copies)
    ssx::SceneModel model = ssx::parseSceneString(xml, label, base_dir, options);
    model.settings.threads = 1;
    model.settings.timing_samples = kTimingSamples;
    envs_ = std::make_unique<ssx::VectorEnvironment>(
        [&](std::size_t i) {
          ssx::Scene scene = ssx::buildScene(model, options);
          scene.environment->setLogSink(toLogging);
          // what loading had to say, once (every copy is the same scene)
          if (i == 0)
            for (const auto& w : scene.warnings) toLogging(ssx::LogLevel::Warning, w.str());
          return scene;
        },
        count, threads.value_or(0));
  }

  ssx::VectorEnvironment& envs() {
    if (!envs_) throw std::runtime_error("ssx: this VectorEnvironment is closed");
    return *envs_;
  }
  std::size_t size() { return envs().size(); }
  std::size_t robots() { return envs().robotNames().size(); }

  void step(std::int64_t n, const py::object& active, const py::object& level, const py::object& commands,
            const py::object& states, const py::object& imu) {
    if (n < 0) throw py::value_error("ssx: step(n) needs n >= 0, got " + std::to_string(n));
    InUse use(busy_);
    ssx::VectorEnvironment& v = envs();
    // commands and readings in the same pass over each copy (VectorEnvironment::step with StepIO)
    ssx::VectorEnvironment::StepIO io;
    Doubles rows;
    py::array_t<double> states_out, imu_out;
    if (!commands.is_none()) {
      if (level.is_none()) throw py::value_error("ssx: step(commands=) needs level= too");
      io.level = commandLevel(py::cast<std::string>(level));
      rows = commandRows(commands);
      io.commands = std::span<const double>(rows.data(), static_cast<std::size_t>(rows.size()));
      io.columns = static_cast<std::size_t>(rows.shape(2));
    }
    if (!states.is_none()) {
      states_out = output(states, ssx::kRobotStateSize, "step(states=)");
      io.states = std::span<double>(states_out.mutable_data(), static_cast<std::size_t>(states_out.size()));
    }
    if (!imu.is_none()) {
      imu_out = output(imu, 6, "step(imu=)");
      io.imu = std::span<double>(imu_out.mutable_data(), static_cast<std::size_t>(imu_out.size()));
    }
    using Flags = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;
    Flags flags;
    if (!active.is_none()) {
      flags = Flags::ensure(active);
      if (!flags || flags.ndim() != 1 || flags.shape(0) != static_cast<py::ssize_t>(v.size()))
        throw py::value_error("ssx: active must be one flag per environment, shape (" + std::to_string(v.size()) +
                              ",)");
    }
    const std::span<const std::uint8_t> mask =
        active.is_none() ? std::span<const std::uint8_t>() : std::span<const std::uint8_t>(flags.data(), v.size());
    try {
      py::gil_scoped_release release;
      if (commands.is_none() && states.is_none() && imu.is_none())
        v.step(n, mask);
      else
        v.step(n, mask, io);
    } catch (const ssx::ConfigError& e) {
      throw py::value_error(configMessage(e));
    }
  }

  static ssx::CommandLevel commandLevel(const std::string& level_name) {
    const auto level = ssx::commandLevelFromName(level_name);
    if (!level)
      throw py::value_error("ssx: unknown command level '" + level_name +
                            "': position, velocity, attitude, rates, rotors or wheels");
    return *level;
  }

  // values as (num_envs, robots, columns) float64 rows (checked: the shape)
  Doubles commandRows(const py::handle& values) {
    Doubles a = Doubles::ensure(values);
    if (!a) throw py::type_error("ssx: values must be an array of numbers");
    if (a.ndim() != 3 || a.shape(0) != static_cast<py::ssize_t>(size()) ||
        a.shape(1) != static_cast<py::ssize_t>(robots()))
      throw py::value_error("ssx: values must have shape (num_envs, robots, columns) = (" + std::to_string(size()) +
                            ", " + std::to_string(robots()) + ", columns)");
    return a;
  }

  void checkCommands(const std::string& level_name, const py::handle& values) {
    InUse use(busy_);
    const ssx::CommandLevel level = commandLevel(level_name);
    const Doubles a = commandRows(values);
    try {
      envs().checkCommands(level, std::span<const double>(a.data(), static_cast<std::size_t>(a.size())),
                           static_cast<std::size_t>(a.shape(2)));
    } catch (const ssx::ConfigError& e) {
      throw py::value_error(configMessage(e));
    }
  }

  // an (E, R, cols) float64 array: `out` when given (checked: shape, dtype, C order, writable), else a new one
  py::array_t<double> output(const py::object& out, std::size_t cols, const char* what) {
    const std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(size()), static_cast<py::ssize_t>(robots()),
                                         static_cast<py::ssize_t>(cols)};
    if (out.is_none()) return py::array_t<double>(shape);
    if (!py::isinstance<py::array_t<double>>(out))
      throw py::type_error(std::string("ssx: ") + what + "(out=) needs a float64 numpy array");
    auto a = py::reinterpret_borrow<py::array_t<double>>(out);
    const bool ok = a.ndim() == 3 && a.shape(0) == shape[0] && a.shape(1) == shape[1] && a.shape(2) == shape[2] &&
                    (a.flags() & py::array::c_style) != 0 && a.writeable();
    if (!ok)
      throw py::value_error(std::string("ssx: ") + what + "(out=) needs a writable C-ordered float64 array of shape (" +
                            std::to_string(shape[0]) + ", " + std::to_string(shape[1]) + ", " +
                            std::to_string(shape[2]) + ")");
    return a;
  }

  py::array_t<double> robotStates(const py::object& out) {
    InUse use(busy_);
    py::array_t<double> a = output(out, ssx::kRobotStateSize, "robot_states");
    envs().robotStates(std::span<double>(a.mutable_data(), static_cast<std::size_t>(a.size())));
    return a;
  }
  py::array_t<double> imu(const py::object& out) {
    InUse use(busy_);
    py::array_t<double> a = output(out, 6, "imu");
    envs().imuReadings(std::span<double>(a.mutable_data(), static_cast<std::size_t>(a.size())));
    return a;
  }

  py::array_t<std::uint8_t> images(const py::object& out) {
    InUse use(busy_);
    try {
      const std::array<std::size_t, 2> hw = envs().imageSize();
      const std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(size()), static_cast<py::ssize_t>(robots()),
                                           static_cast<py::ssize_t>(hw[0]), static_cast<py::ssize_t>(hw[1]), 3};
      py::array_t<std::uint8_t> a;
      if (out.is_none()) {
        a = py::array_t<std::uint8_t>(shape);
      } else {
        if (!py::isinstance<py::array_t<std::uint8_t>>(out))
          throw py::type_error("ssx: images(out=) needs a uint8 numpy array");
        a = py::reinterpret_borrow<py::array_t<std::uint8_t>>(out);
        bool ok = a.ndim() == 5 && (a.flags() & py::array::c_style) != 0 && a.writeable();
        for (int d = 0; ok && d < 5; ++d) ok = a.shape(d) == shape[static_cast<std::size_t>(d)];
        if (!ok)
          throw py::value_error("ssx: images(out=) needs a writable C-ordered uint8 array of shape (" +
                                std::to_string(shape[0]) + ", " + std::to_string(shape[1]) + ", " +
                                std::to_string(shape[2]) + ", " + std::to_string(shape[3]) + ", 3)");
      }
      std::span<std::uint8_t> bytes(a.mutable_data(), static_cast<std::size_t>(a.size()));
      py::gil_scoped_release release;
      envs().cameraImages(bytes);
      return a;
    } catch (const ssx::ConfigError& e) {
      throw py::value_error(configMessage(e));
    }
  }

  py::array_t<double> read(const std::string& kind, const py::object& out, std::size_t slots) {
    InUse use(busy_);
    try {
      const std::size_t width = envs().sensorWidth(kind, slots);
      py::array_t<double> a = output(out, width, "read");
      envs().readSensors(kind, std::span<double>(a.mutable_data(), static_cast<std::size_t>(a.size())), slots);
      return a;
    } catch (const ssx::ConfigError& e) {
      throw py::value_error(configMessage(e));
    }
  }

  void setCommands(const std::string& level_name, const py::handle& values) {
    InUse use(busy_);
    const ssx::CommandLevel level = commandLevel(level_name);
    const Doubles a = commandRows(values);
    try {
      // (the drivers take them on the worker threads, where a plugin's log line needs the GIL)
      const std::span<const double> rows(a.data(), static_cast<std::size_t>(a.size()));
      const auto columns = static_cast<std::size_t>(a.shape(2));
      ssx::VectorEnvironment& v = envs();
      py::gil_scoped_release release;
      v.setCommands(level, rows, columns);
    } catch (const ssx::ConfigError& e) {
      throw py::value_error(configMessage(e));
    }
  }

  std::vector<std::size_t> indices(const py::handle& which) {
    std::vector<std::size_t> out;
    for (const py::handle item : py::reinterpret_borrow<py::sequence>(which)) {
      const auto i = py::int_(py::reinterpret_borrow<py::object>(item)).cast<long long>();
      if (i < 0 || static_cast<std::size_t>(i) >= size())
        throw py::index_error("ssx: environment index " + std::to_string(i) + " is outside 0.." +
                              std::to_string(size() - 1));
      out.push_back(static_cast<std::size_t>(i));
    }
    return out;
  }

  py::bytes saveState(std::size_t i) {
    InUse use(busy_);
    ssx::Environment& env = envs()[i];
    std::vector<std::byte> state;
    {
      py::gil_scoped_release release;
      state = env.saveState();
    }
    return {reinterpret_cast<const char*>(state.data()), state.size()};
  }

  void reset(const py::handle& which, const py::bytes& state, const std::vector<std::uint64_t>& seeds) {
    InUse use(busy_);
    const std::vector<std::size_t> chosen = indices(which);
    const std::string_view view = state;
    const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(view.data()), view.size());
    ssx::VectorEnvironment& v = envs();
    try {
      py::gil_scoped_release release;
      v.reset(chosen, bytes, seeds);
    } catch (const ssx::ConfigError& e) {
      throw py::value_error(configMessage(e));
    }
  }

  void moveRobots(const py::handle& which, const py::handle& offsets, const py::handle& velocities) {
    InUse use(busy_);
    const std::vector<std::size_t> chosen = indices(which);
    const auto rows = static_cast<py::ssize_t>(chosen.size());
    auto check = [&](const py::handle& h, const char* what) {
      Doubles a = Doubles::ensure(h);
      if (!a || a.ndim() != 3 || a.shape(0) != rows || a.shape(1) != static_cast<py::ssize_t>(robots()) ||
          a.shape(2) != 3)
        throw py::value_error(std::string("ssx: ") + what + " must have shape (" + std::to_string(rows) + ", " +
                              std::to_string(robots()) + ", 3): one row per robot of each environment named");
      return a;
    };
    const Doubles off = check(offsets, "offsets");
    std::optional<Doubles> vel;
    if (!velocities.is_none()) vel = check(velocities, "velocities");
    try {
      envs().moveRobots(chosen, std::span<const double>(off.data(), static_cast<std::size_t>(off.size())),
                        vel ? std::span<const double>(vel->data(), static_cast<std::size_t>(vel->size()))
                            : std::span<const double>());
    } catch (const ssx::ConfigError& e) {
      throw py::value_error(configMessage(e));
    }
  }

  py::list variables(std::size_t robot) {
    py::list out;
    for (const ssx::Variable& v : envs().variables(robot)) out.append(variableDict(v));
    return out;
  }

  void vary(const py::handle& which, const std::string& name, const py::handle& values) {
    InUse use(busy_);
    const std::vector<std::size_t> chosen = indices(which);
    const Doubles a = Doubles::ensure(values);
    if (!a || a.ndim() != 2 || a.shape(0) != static_cast<py::ssize_t>(chosen.size()) ||
        a.shape(1) != static_cast<py::ssize_t>(robots()))
      throw py::value_error("ssx: vary values must have shape (" + std::to_string(chosen.size()) + ", " +
                            std::to_string(robots()) + "): one per robot of each environment named");
    ssx::VectorEnvironment& v = envs();
    try {
      py::gil_scoped_release release;
      v.vary(chosen, name, std::span<const double>(a.data(), static_cast<std::size_t>(a.size())));
    } catch (const ssx::ConfigError& e) {
      throw py::value_error(configMessage(e));
    }
  }

  void setCommandDelays(const py::handle& which, const py::handle& steps) {
    InUse use(busy_);
    const std::vector<std::size_t> chosen = indices(which);
    using Steps = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
    const Steps a = Steps::ensure(steps);
    if (!a || a.ndim() != 2 || a.shape(0) != static_cast<py::ssize_t>(chosen.size()) ||
        a.shape(1) != static_cast<py::ssize_t>(robots()))
      throw py::value_error("ssx: command delays must have shape (" + std::to_string(chosen.size()) + ", " +
                            std::to_string(robots()) + "): steps per robot of each environment named");
    try {
      envs().setCommandDelays(chosen, std::span<const std::int64_t>(a.data(), static_cast<std::size_t>(a.size())));
    } catch (const ssx::ConfigError& e) {
      throw py::value_error(configMessage(e));
    }
  }

  void recordContacts(bool on) {
    InUse use(busy_);
    envs().recordContacts(on);
  }
  py::list contacts(std::size_t i) {
    InUse use(busy_);
    if (i >= size()) throw py::index_error("ssx: no environment " + std::to_string(i));
    return contactList(envs()[i]);
  }
  py::array_t<double> contactImpulses(const py::object& out) {
    InUse use(busy_);
    py::array_t<double> a = output(out, 2, "contact_impulses");
    envs().contactImpulses(std::span<double>(a.mutable_data(), static_cast<std::size_t>(a.size())));
    return a;
  }

  py::array_t<std::uint64_t> stateHashes() {
    InUse use(busy_);
    py::array_t<std::uint64_t> out(static_cast<py::ssize_t>(size()));
    for (std::size_t i = 0; i < size(); ++i) out.mutable_data()[i] = envs()[i].stateHash();
    return out;
  }
  py::array_t<double> times() {
    InUse use(busy_);
    py::array_t<double> out(static_cast<py::ssize_t>(size()));
    for (std::size_t i = 0; i < size(); ++i) out.mutable_data()[i] = ssx::toSeconds(envs()[i].time());
    return out;
  }
  double timestep() { return ssx::toSeconds(envs()[0].timestep()); }
  unsigned threads() { return envs().threadCount(); }
  std::vector<std::string> robotNames() { return envs().robotNames(); }
  void close() {
    InUse use(busy_);
    py::gil_scoped_release release;
    envs_.reset();
  }

 private:
  std::unique_ptr<ssx::VectorEnvironment> envs_;
  std::atomic<bool> busy_{false};
};

}  // namespace

py::list contactList(const ssx::Environment& env) {
  // ssx.Contact, made when the module was imported (bindVectorEnvironment)
  const py::object contact = py::module_::import("ssx._ssx").attr("Contact");
  py::list out;
  for (const ssx::EngineContact& c : env.contacts())
    out.append(contact(env.bodyOwner(c.body_a).name(), env.contactOther(c).name(), c.impulse, vector3(c.position),
                       vector3(c.normal), c.body_b < 0));
  return out;
}

namespace {

std::vector<const ssx::Artifact*> robotsOf(const ssx::Environment& env) {
  std::vector<const ssx::Artifact*> robots;
  for (std::size_t a = 0; a < env.artifactCount(); ++a)
    if (dynamic_cast<const ssx::SetpointInterface*>(env.artifact(a).driver()) != nullptr)
      robots.push_back(&env.artifact(a));
  return robots;
}

// `out` when it is a writable C-ordered array of T of `shape`, else a new one (None), else an error
template <class T>
py::array_t<T> outputOf(const py::object& out, const std::vector<py::ssize_t>& shape, const char* what,
                        const char* dtype) {
  if (out.is_none()) return py::array_t<T>(shape);
  if (!py::isinstance<py::array_t<T>>(out))
    throw py::type_error(std::string("ssx: ") + what + "(out=) needs a " + dtype + " numpy array");
  auto a = py::reinterpret_borrow<py::array_t<T>>(out);
  bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size()) && (a.flags() & py::array::c_style) != 0 &&
            a.writeable();
  for (std::size_t d = 0; ok && d < shape.size(); ++d) ok = a.shape(static_cast<py::ssize_t>(d)) == shape[d];
  if (!ok) {
    std::string s;
    for (const py::ssize_t n : shape) s += (s.empty() ? "" : ", ") + std::to_string(n);
    throw py::value_error(std::string("ssx: ") + what + "(out=) needs a writable C-ordered " + dtype +
                          " array of shape (" + s + ")");
  }
  return a;
}

}  // namespace

py::object readRobots(const ssx::Environment& env, const std::string& kind, const py::object& out, std::size_t slots) {
  const std::vector<const ssx::Artifact*> robots = robotsOf(env);
  try {
    const std::size_t width = ssx::sensorWidth(robots, kind, slots);
    py::array_t<double> a = outputOf<double>(
        out, {static_cast<py::ssize_t>(robots.size()), static_cast<py::ssize_t>(width)}, "read", "float64");
    ssx::readSensors(robots, kind, std::span<double>(a.mutable_data(), static_cast<std::size_t>(a.size())), slots);
    return a;
  } catch (const ssx::ConfigError& e) {
    throw py::value_error(configMessage(e));
  }
}

py::object robotImages(const ssx::Environment& env, const py::object& out) {
  const std::vector<const ssx::Artifact*> robots = robotsOf(env);
  try {
    const std::array<std::size_t, 2> hw = ssx::imageSize(robots);
    py::array_t<std::uint8_t> a = outputOf<std::uint8_t>(out,
                                                         {static_cast<py::ssize_t>(robots.size()),
                                                          static_cast<py::ssize_t>(hw[0]),
                                                          static_cast<py::ssize_t>(hw[1]), 3},
                                                         "images", "uint8");
    ssx::cameraImages(robots, std::span<std::uint8_t>(a.mutable_data(), static_cast<std::size_t>(a.size())));
    return a;
  } catch (const ssx::ConfigError& e) {
    throw py::value_error(configMessage(e));
  }
}

py::dict variableDict(const ssx::Variable& v) {
  py::dict d;
  d["name"] = v.name;
  d["neutral"] = v.neutral;
  d["min"] = v.min;
  d["max"] = v.max;
  d["doc"] = v.doc;
  return d;
}

void bindVectorEnvironment(py::module_& m) {
  py::object contact = py::module_::import("collections")
                           .attr("namedtuple")("Contact", "artifact other impulse position normal static",
                                               py::arg("module") = "ssx");
  contact.attr("__doc__") =
      "One pair touching in the last step: artifact (a robot or item), other (what it touched: another robot or item, "
      "or the static artifact, the ground or a wall), impulse (N s, normal, summed over the step), position (m) and "
      "normal (from other towards artifact) of the deepest point, static (other is static).";
  m.attr("Contact") = contact;
  py::class_<PyVectorEnvironment>(m, "VectorEnvironment",
                                  "num_envs copies of one scene, each a world of its own, stepped together on a pool "
                                  "of threads (the GIL released): the core of ssx.learn.VectorEnv.")
      .def(py::init<const std::string&, std::size_t, const fs::path&, std::optional<std::uint64_t>, std::optional<int>,
                    const std::string&, const std::vector<fs::path>&, const std::optional<std::string>&>(),
           py::arg("xml"), py::arg("num_envs"), py::arg("base_dir") = fs::path("."), py::arg("seed") = py::none(),
           py::arg("threads") = py::none(), py::arg("label") = "<string>",
           py::arg("plugin_path") = std::vector<fs::path>{}, py::arg("physics") = py::none())
      .def_property_readonly("num_envs", &PyVectorEnvironment::size)
      .def_property_readonly("robot_names", &PyVectorEnvironment::robotNames,
                             "The robots of every copy (drivers that take set-points), in artifact order.")
      .def_property_readonly("timestep", &PyVectorEnvironment::timestep, "Physics timestep, s.")
      .def_property_readonly("threads", &PyVectorEnvironment::threads, "Threads stepping the copies.")
      .def("step", &PyVectorEnvironment::step, py::arg("n") = 1, py::arg("active") = py::none(),
           py::arg("level") = py::none(), py::arg("commands") = py::none(), py::arg("states") = py::none(),
           py::arg("imu") = py::none(),
           "Steps every copy n times (GIL released); active: one flag per copy, only those flagged step. With "
           "commands= (and level=, as set_commands), states= and imu= (arrays as robot_states and imu fill), a "
           "learning step in one pass over each copy: its rows sent, its steps, its readings; the copies not "
           "flagged active are not sent theirs (checked all the same).")
      .def("check_commands", &PyVectorEnvironment::checkCommands, py::arg("level"), py::arg("values"),
           "Checks commands as set_commands does (ValueError naming the copy and robot), sending none.")
      .def("robot_states", &PyVectorEnvironment::robotStates, py::arg("out") = py::none(),
           "(num_envs, robots, 13): x y z, qw qx qy qz, vx vy vz, wx wy wz (world frame); into out= when given.")
      .def("imu", &PyVectorEnvironment::imu, py::arg("out") = py::none(),
           "(num_envs, robots, 6): each robot's first IMU, accelerometer (m/s^2) then gyroscope (rad/s).")
      .def("read", &PyVectorEnvironment::read, py::arg("kind"), py::arg("out") = py::none(), py::arg("slots") = 0,
           "(num_envs, robots, width): one kind of sensor of every robot: pose (13), proximity (per ray), ground (per "
           "point), range (5 per slot: present, x, y, z, distance), range_and_bearing (4 per slot: present, range, "
           "bearing, elevation), odometry (9); slots: how many detections or messages; into out= when given.")
      .def("images", &PyVectorEnvironment::images, py::arg("out") = py::none(),
           "Every robot's latest camera image, (num_envs, robots, height, width, 3) uint8 RGB, rows from the top, "
           "from its first camera sensor (into out when given).")
      .def("set_commands", &PyVectorEnvironment::setCommands, py::arg("level"), py::arg("values"),
           "One command level for every robot: values (num_envs, robots, columns), checked whole first.")
      .def("save_state", &PyVectorEnvironment::saveState, py::arg("index") = 0, "Copy index's state, as bytes.")
      .def("reset", &PyVectorEnvironment::reset, py::arg("indices"), py::arg("state"), py::arg("seeds"),
           "Restores the copies named to state and reseeds their random streams, one seed each (GIL released).")
      .def("move_robots", &PyVectorEnvironment::moveRobots, py::arg("indices"), py::arg("offsets"),
           py::arg("velocities") = py::none(),
           "Moves every robot of the copies named by offsets (len(indices), robots, 3), at velocities (or at rest).")
      .def("variables", &PyVectorEnvironment::variables, py::arg("robot") = 0,
           "What vary takes for robot index robot: dicts of name, neutral, min, max, doc.")
      .def("vary", &PyVectorEnvironment::vary, py::arg("indices"), py::arg("name"), py::arg("values"),
           "Sets constant name ('mass', 'inertia' or a plugin's variable) of every robot of the copies named to "
           "values (len(indices), robots), checked whole first (GIL released).")
      .def("set_command_delays", &PyVectorEnvironment::setCommandDelays, py::arg("indices"), py::arg("steps"),
           "Actuation latency: robot r of environment indices[k] takes each later set_commands steps[k, r] physics "
           "steps into the steps that follow (0: at once), holding the one before until then. Not in saved states; "
           "reset drops the commands waiting.")
      .def("record_contacts", &PyVectorEnvironment::recordContacts, py::arg("on") = true,
           "Every copy keeps the contacts of its steps from now on (off by default).")
      .def("contact_list", &PyVectorEnvironment::contacts, py::arg("index"),
           "Copy index's last-step contacts: ssx.Contact(artifact, other, impulse N s, position, normal, static).")
      .def("contact_impulses", &PyVectorEnvironment::contactImpulses, py::arg("out") = py::none(),
           "(num_envs, robots, 2): each robot's normal impulse (N s) in the last step from the static world and from "
           "other bodies.")
      .def("state_hashes", &PyVectorEnvironment::stateHashes, "Each copy's state hash (uint64).")
      .def("times", &PyVectorEnvironment::times, "Each copy's simulated time, s.")
      .def("close", &PyVectorEnvironment::close, "Stops and frees every copy.");
}

}  // namespace ssx_python
