#include "commands.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <unordered_map>

namespace ssx_python {

Array requireRows(const py::handle& value, py::ssize_t rows, py::ssize_t cols, const char* what) {
  Array a = Array::ensure(value);
  if (!a) throw py::type_error(std::string("ssx: ") + what + " must be an array of numbers");
  const bool shape_ok = cols == 0 ? (a.ndim() == 1 && a.shape(0) == rows)
                                  : (a.ndim() == 2 && a.shape(0) == rows && a.shape(1) == cols);
  if (!shape_ok) {
    std::string got = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) got += (i ? ", " : "") + std::to_string(a.shape(i));
    got += a.ndim() == 1 ? ",)" : ")";
    throw py::value_error(std::string("ssx: ") + what + " must have shape (" + std::to_string(rows) +
                          (cols == 0 ? ",)" : ", " + std::to_string(cols) + ")") + ", one row per robot commanded (" +
                          "Environment.setpoint_names(), or robots=), got " + got);
  }
  const double* p = a.data();
  for (py::ssize_t i = 0; i < a.size(); ++i)
    if (!std::isfinite(p[i]))
      throw py::value_error(std::string("ssx: ") + what + " holds a NaN or an infinity (row " +
                            std::to_string(cols == 0 ? i : i / cols) + ")");
  return a;
}

CommandTargets::CommandTargets(ssx::Environment& env) {
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    ssx::Artifact& a = env.artifact(i);
    if (auto* s = dynamic_cast<ssx::SetpointInterface*>(a.driver())) {
      artifacts_.push_back(&a);
      setpoint_.push_back(s);
      command_.push_back(dynamic_cast<ssx::CommandInterface*>(s));
    }
  }
}

std::vector<std::string> CommandTargets::names() const {
  std::vector<std::string> names;
  names.reserve(artifacts_.size());
  for (const ssx::Artifact* a : artifacts_) names.push_back(a->name());
  return names;
}

std::vector<std::size_t> CommandTargets::select(const py::handle& robots) const {
  if (artifacts_.empty()) throw std::runtime_error("ssx: no artifact of this scene has a driver that takes commands");
  std::vector<std::size_t> rows;
  if (robots.is_none()) {
    for (std::size_t i = 0; i < artifacts_.size(); ++i) rows.push_back(i);
    return rows;
  }
  if (py::isinstance<py::str>(robots) || !py::isinstance<py::sequence>(robots))
    throw py::type_error("ssx: robots must be a list of names or indices (Environment.setpoint_names())");
  std::unordered_map<std::string, std::size_t> by_name;
  for (std::size_t i = 0; i < artifacts_.size(); ++i) by_name.emplace(artifacts_[i]->name(), i);
  std::vector<bool> taken(artifacts_.size(), false);
  for (const py::handle item : py::reinterpret_borrow<py::sequence>(robots)) {
    std::size_t row = 0;
    if (py::isinstance<py::str>(item)) {
      const auto name = item.cast<std::string>();
      const auto it = by_name.find(name);
      if (it == by_name.end())
        throw py::key_error("ssx: no robot named '" + name + "' takes commands (Environment.setpoint_names())");
      row = it->second;
    } else if (!py::isinstance<py::bool_>(item) && (py::isinstance<py::int_>(item) || py::hasattr(item, "__index__"))) {
      const auto index = py::int_(py::reinterpret_borrow<py::object>(item)).cast<long long>();
      if (index < 0 || static_cast<std::size_t>(index) >= artifacts_.size())
        throw py::index_error("ssx: robot index " + std::to_string(index) + " is outside 0.." +
                              std::to_string(artifacts_.size() - 1) + " (Environment.setpoint_names())");
      row = static_cast<std::size_t>(index);
    } else {
      throw py::type_error("ssx: robots must be a list of names or indices (Environment.setpoint_names())");
    }
    if (taken[row]) throw py::value_error("ssx: robot '" + artifacts_[row]->name() + "' is named twice in robots");
    taken[row] = true;
    rows.push_back(row);
  }
  return rows;
}

void CommandTargets::setCommands(const std::string& level_name, const py::handle& values, const py::handle& robots) {
  const auto level = ssx::commandLevelFromName(level_name);
  if (!level)
    throw py::value_error("ssx: unknown command level '" + level_name +
                          "': position, velocity, attitude, rates, rotors or wheels");
  const std::vector<std::size_t> rows = select(robots);
  const Array a = Array::ensure(values);
  if (!a) throw py::type_error("ssx: values must be an array of numbers");
  if (a.ndim() != 2 || a.shape(0) != static_cast<py::ssize_t>(rows.size()))
    throw py::value_error("ssx: values must be a 2-D array with one row per robot commanded (" +
                          std::to_string(rows.size()) + ")");
  const auto cols = static_cast<std::size_t>(a.shape(1));
  // every row checked (its size, its numbers, what its robot takes) before any robot gets one
  std::vector<ssx::Command> commands;
  commands.reserve(rows.size());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const std::size_t t = rows[r];
    const std::string who = "robot '" + artifacts_[t]->name() + "' (row " + std::to_string(r) + ")";
    ssx::CommandInterface* target = command_[t];
    if (target == nullptr && *level != ssx::CommandLevel::Position)
      throw py::value_error("ssx: " + who + " takes set-points only, no commands at the " + level_name + " level");
    const std::size_t rotors = target != nullptr ? target->rotorCount() : 0;
    if (!ssx::Command::rowSizeFits(*level, cols, rotors))
      throw py::value_error("ssx: a " + level_name + " command for " + who + " has " +
                            ssx::Command::rowSizes(*level, rotors) + " values, got " + std::to_string(cols));
    const double* row = a.data() + r * cols;
    commands.push_back(ssx::Command::fromRow(*level, std::span<const double>(row, cols)));
    const std::string why = target != nullptr ? target->refusal(commands.back()) : commands.back().problem();
    if (!why.empty()) throw py::value_error("ssx: " + who + ": " + why);
  }
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (command_[rows[r]] != nullptr)
      command_[rows[r]]->setCommand(commands[r]);
    else
      setpoint_[rows[r]]->setSetpoint(commands[r].setpoint);
  }
}

void CommandTargets::setSetpoints(const py::handle& positions, const py::handle& velocities, const py::handle& yaws,
                                  const py::handle& accelerations, const py::handle& yaw_rates,
                                  const py::handle& robots) {
  const std::vector<std::size_t> rows = select(robots);
  const auto n = static_cast<py::ssize_t>(rows.size());
  const Array pos = requireRows(positions, n, 3, "positions");
  std::optional<Array> vel, acc, yaw, rate;
  if (!velocities.is_none()) vel = requireRows(velocities, n, 3, "velocities");
  if (!accelerations.is_none()) acc = requireRows(accelerations, n, 3, "accelerations");
  if (!yaws.is_none()) yaw = requireRows(yaws, n, 0, "yaws");
  if (!yaw_rates.is_none()) rate = requireRows(yaw_rates, n, 0, "yaw_rates");
  for (py::ssize_t i = 0; i < n; ++i) {
    ssx::Setpoint sp;
    sp.position = ssx::Vec3(pos.at(i, 0), pos.at(i, 1), pos.at(i, 2));
    if (vel) sp.velocity = ssx::Vec3(vel->at(i, 0), vel->at(i, 1), vel->at(i, 2));
    if (acc) sp.acceleration = ssx::Vec3(acc->at(i, 0), acc->at(i, 1), acc->at(i, 2));
    if (yaw) sp.yaw = yaw->at(i);
    if (rate) sp.yaw_rate = rate->at(i);
    setpoint_[rows[static_cast<std::size_t>(i)]]->setSetpoint(sp);
  }
}

}  // namespace ssx_python
