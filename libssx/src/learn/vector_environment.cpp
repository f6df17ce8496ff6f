// Many copies of one scene stepped together (ssx/vector_environment.hpp).
#include "base/exceptions.hpp"
#include "base/worker_pool.hpp"

#include <ssx/command.hpp>
#include <ssx/error.hpp>
#include <ssx/measurements.hpp>
#include <ssx/vector_environment.hpp>

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

namespace ssx {

struct VectorEnvironment::Pool {
  Pool(unsigned threads, std::size_t copies) : workers(threads), errors(copies) {}
  detail::WorkerPool workers;
  std::vector<std::exception_ptr> errors;  // per copy, of the current forEach
};

namespace {

unsigned poolSize(int threads, std::size_t copies) {
  if (threads < 0)
    throw ConfigError({}, "a vector environment needs threads >= 0 (0: one per core), got " + std::to_string(threads));
  unsigned n = threads > 0 ? static_cast<unsigned>(threads) : std::max(1u, std::thread::hardware_concurrency());
  if (copies > 0 && n > copies) n = static_cast<unsigned>(copies);
  return std::max(1u, n);
}

}  // namespace

VectorEnvironment::VectorEnvironment(const std::function<Scene(std::size_t)>& load, std::size_t count, int threads) {
  if (count == 0) throw ConfigError({}, "a vector environment needs at least one copy");
  const unsigned pool_threads = poolSize(threads, count);
  scenes_.reserve(count);
  envs_.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    scenes_.push_back(load(i));
    Environment& env = *scenes_.back().environment;
    if (env.settings().threads != 1)
      throw ConfigError(
          {},
          "copy " + std::to_string(i) + " of a vector environment steps on " + std::to_string(env.settings().threads) +
              " threads; load each copy with one (SceneOptions::threads = 1): the copies are what runs in parallel");
    std::vector<std::string> names;
    for (std::size_t a = 0; a < env.artifactCount(); ++a) {
      Artifact& artifact = env.artifact(a);
      auto* setpoint = dynamic_cast<SetpointInterface*>(artifact.driver());
      if (setpoint == nullptr) continue;
      names.push_back(artifact.name());
      roots_.push_back(&std::as_const(artifact).root());
      setpoints_.push_back(setpoint);
      commands_.push_back(dynamic_cast<CommandInterface*>(setpoint));
      artifacts_.push_back(&artifact);
      const Sensor* imu = nullptr;
      for (std::size_t k = 0; k < artifact.sensorCount() && imu == nullptr; ++k)
        if (dynamic_cast<const ImuMeasurement*>(&std::as_const(artifact).sensor(k).latest()) != nullptr)
          imu = &std::as_const(artifact).sensor(k);
      imus_.push_back(imu);
    }
    if (i == 0) {
      robot_names_ = std::move(names);
    } else if (names != robot_names_) {
      std::size_t k = 0;
      while (k < names.size() && k < robot_names_.size() && names[k] == robot_names_[k]) ++k;
      throw ConfigError({}, "copy " + std::to_string(i) +
                                " of a vector environment has other robots than copy 0: robot " + std::to_string(k) +
                                " is '" + (k < names.size() ? names[k] : std::string("(none)")) + "' there and '" +
                                (k < robot_names_.size() ? robot_names_[k] : std::string("(none)")) +
                                "' in copy 0; every copy must be the same scene");
    } else if (env.sceneFingerprint() != envs_[0]->sceneFingerprint()) {
      // (a state saved from one copy must fit every other: reset checks it once for all)
      throw ConfigError({}, "copy " + std::to_string(i) +
                                " of a vector environment is not the same scene as copy 0 "
                                "(its timestep, bodies or plugins differ); every copy must be the same scene");
    }
    envs_.push_back(&env);
  }
  pool_ = std::make_unique<Pool>(pool_threads, count);
  forEach([&](std::size_t i) { envs_[i]->start(); });
  hot_lines_.resize(count * kHotLines);
  hot_count_.resize(count);
  forEach([&](std::size_t i) { findHotLines(i); });
  // bodies are numbered at start
  for (const Artifact* artifact : artifacts_) {
    std::vector<int> bodies;
    for (std::size_t k = 0; k < artifact->nodeCount(); ++k) {
      const int b = artifact->nodeAt(k).bodyIndex();
      if (b >= 0 && !artifact->nodeAt(k).isStatic() && std::find(bodies.begin(), bodies.end(), b) == bodies.end())
        bodies.push_back(b);
    }
    bodies_.push_back(std::move(bodies));
  }
  for (std::size_t r = 0; r < robot_names_.size(); ++r) {
    const CommandInterface* driver = commands_[r];
    std::uint8_t levels = 0;
    for (const CommandLevel level : kCommandLevels)
      if (driver != nullptr && driver->acceptsCommand(level))
        levels |= static_cast<std::uint8_t>(1u << static_cast<unsigned>(level));
    accepts_.push_back(levels);
    rotor_counts_.push_back(driver != nullptr ? driver->rotorCount() : 0);
  }
  robot_of_body_.assign(envs_[0]->bodyCount(), -1);
  for (std::size_t r = 0; r < robot_names_.size(); ++r)
    for (const int b : bodies_[r]) robot_of_body_[static_cast<std::size_t>(b)] = static_cast<int>(r);
}

VectorEnvironment::~VectorEnvironment() = default;

Environment& VectorEnvironment::operator[](std::size_t i) {
  if (i >= envs_.size())
    throw std::out_of_range("ssx: copy " + std::to_string(i) + " of a vector environment of " +
                            std::to_string(envs_.size()));
  return *envs_[i];
}

unsigned VectorEnvironment::threadCount() const noexcept { return pool_->workers.size(); }

void VectorEnvironment::forEach(const std::function<void(std::size_t)>& fn) {
  forEachOf({}, [&](std::size_t i, std::size_t) { fn(i); });
}

void VectorEnvironment::forEachOf(std::span<const std::size_t> which,
                                  const std::function<void(std::size_t, std::size_t)>& fn) {
  // every copy is attempted; the first failure by index is rethrown after the barrier, so which
  // error a caller sees does not depend on the threads' timing
  std::vector<std::exception_ptr>& errors = pool_->errors;  // kept: no allocation per step
  auto body = [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t i = which.empty() ? k : which[k];
      try {
        fn(i, k);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  const std::size_t n = which.empty() ? envs_.size() : which.size();
  if (n == 1)
    body(0, 1);  // one copy (a reset in the middle of a batch): waking the pool would cost more
  else
    pool_->workers.parallelFor(n, 1, body);
  rethrowFirst();
}

void VectorEnvironment::findHotLines(std::size_t i) {
  std::vector<MemoryRange> ranges;
  envs_[i]->hotMemory(ranges);
  const char** line = hot_lines_.data() + i * kHotLines;
  std::size_t count = 0;
  for (const MemoryRange& range : ranges) {
    const auto first = reinterpret_cast<std::uintptr_t>(range.address) & ~std::uintptr_t{63};
    const auto end = reinterpret_cast<std::uintptr_t>(range.address) + range.bytes;
    for (std::uintptr_t at = first; at < end && count < kHotLines; at += 64)
      if (count == 0 || line[count - 1] != reinterpret_cast<const char*>(at))
        line[count++] = reinterpret_cast<const char*>(at);
  }
  hot_count_[i] = static_cast<std::uint16_t>(count);
}

void VectorEnvironment::rethrowFirst() {
  std::vector<std::exception_ptr>& errors = pool_->errors;
  const auto first = std::find_if(errors.begin(), errors.end(), [](const auto& e) { return static_cast<bool>(e); });
  if (first == errors.end()) return;
  std::vector<std::exception_ptr> failed;
  failed.swap(errors);
  errors.resize(envs_.size());
  for (std::size_t i = 0; i < failed.size(); ++i)
    if (failed[i]) {
      try {
        std::rethrow_exception(failed[i]);
      } catch (const StateError& e) {
        throw StateError("copy " + std::to_string(i) + ": " + e.what());
      } catch (const ConfigError& e) {
        throw ConfigError(e.where(), "copy " + std::to_string(i) + ": " + e.detail());
      } catch (const StepError& e) {
        // the same failure, said to be copy i's (what() less the prefix StepError puts before it)
        const std::string prefix =
            "step " + std::to_string(e.step()) + ": artifact '" + e.artifact() + "', " + e.plugin() + ": ";
        const std::string what = e.what();
        throw StepError(e.artifact(), e.plugin(), e.step(),
                        (what.starts_with(prefix) ? what.substr(prefix.size()) : what) + " (copy " + std::to_string(i) +
                            " of the vector environment)");
      } catch (...) {
        throw Error("copy " + std::to_string(i) + ": " + detail::describe(failed[i]));
      }
    }
}

void VectorEnvironment::step(std::int64_t n, std::span<const std::uint8_t> active) { step(n, active, StepIO{}); }

void VectorEnvironment::step(std::int64_t n, std::span<const std::uint8_t> active, const StepIO& io) {
  if (n < 0) throw ConfigError({}, "a vector environment steps n >= 0 times, got " + std::to_string(n));
  if (!active.empty() && active.size() != envs_.size())
    throw ConfigError({}, "a vector environment of " + std::to_string(envs_.size()) + " copies was given " +
                              std::to_string(active.size()) + " flags of which copies step");
  if (!io.states.empty()) checkOutput(io.states, kRobotStateSize, "robotStates");
  if (!io.imu.empty()) {
    checkOutput(io.imu, 6, "imuReadings");
    checkImus();
  }
  const bool commanded = !io.commands.empty();
  if (commanded) stageCommands(io.level, io.commands, io.columns);
  const std::size_t robots = robot_names_.size();
  forEachInChunks([&](std::size_t i) {
    if (active.empty() || active[i] != 0) {
      if (commanded) deliverCommands(i);
      if (n > 0) stepCopy(i, n);
    }
    if (!io.states.empty()) readStates(i, i + 1, io.states.data() + i * robots * kRobotStateSize);
    if (!io.imu.empty()) readImu(i, i + 1, io.imu.data() + i * robots * 6);
  });
}

void VectorEnvironment::forEachInChunks(Ref<std::size_t> fn) {
  std::vector<std::exception_ptr>& errors = pool_->errors;
  const std::size_t n = envs_.size();
  auto body = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (i + 1 < end) {
        const char* const* line = hot_lines_.data() + (i + 1) * kHotLines;
        for (std::size_t k = 0; k < hot_count_[i + 1]; ++k) __builtin_prefetch(line[k]);
      }
      try {
        fn(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  // runs of copies that shrink as the batch runs out: no thread waits long at the end for the
  // other's last run (a run of 64 copies of 1,024 is 0.6 ms of a 6 ms batch)
  pool_->workers.parallelForGuided(n, 4, body);
  rethrowFirst();
}

void VectorEnvironment::stepCopy(std::size_t i, std::int64_t n) {
  if (copy_waits_.empty() || copy_waits_[i] == 0) {
    envs_[i]->step(n);
    return;
  }
  const std::size_t robots = robot_names_.size(), first = i * robots;
  std::int64_t left = n;
  bool waits = true;
  while (left > 0 && waits) {
    std::int64_t next = left;  // steps until the next command waiting is due (or the end)
    for (std::size_t r = first; r < first + robots; ++r)
      if (remaining_[r] >= 0) next = std::min(next, remaining_[r]);
    envs_[i]->step(next);
    left -= next;
    waits = false;
    for (std::size_t r = first; r < first + robots; ++r) {
      if (remaining_[r] < 0) continue;
      remaining_[r] -= next;
      if (remaining_[r] == 0) {
        send(r, waiting_[r]);
        remaining_[r] = -1;
      } else {
        waits = true;
      }
    }
  }
  copy_waits_[i] = waits ? 1 : 0;
  envs_[i]->step(left);
}

void VectorEnvironment::setCommandDelays(std::span<const std::size_t> which, std::span<const std::int64_t> steps) {
  const std::size_t robots = robot_names_.size();
  if (steps.size() != which.size() * robots)
    throw ConfigError({}, "command delays for " + std::to_string(which.size()) + " copies of " + std::to_string(robots) +
                              " robots need " + std::to_string(which.size() * robots) + " numbers, got " +
                              std::to_string(steps.size()));
  checkWhich(which, "setting command delays");
  for (std::size_t k = 0; k < steps.size(); ++k)
    if (steps[k] < 0)
      throw ConfigError({}, "copy " + std::to_string(which[k / robots]) + ", robot '" + robot_names_[k % robots] +
                                "': a command delay is >= 0 steps, got " + std::to_string(steps[k]));
  if (delays_.empty()) {
    const std::size_t rows = envs_.size() * robots;
    delays_.assign(rows, 0);
    remaining_.assign(rows, -1);
    waiting_.assign(rows, Command{});
    copy_waits_.assign(envs_.size(), 0);
  }
  for (std::size_t k = 0; k < which.size(); ++k)
    std::copy_n(steps.begin() + static_cast<std::ptrdiff_t>(k * robots), robots,
                delays_.begin() + static_cast<std::ptrdiff_t>(which[k] * robots));
}

void VectorEnvironment::reset(std::span<const std::size_t> which, std::span<const std::byte> state,
                              std::span<const std::uint64_t> seeds) {
  if (seeds.size() != which.size())
    throw ConfigError({}, "a reset names " + std::to_string(which.size()) + " copies and gives " +
                              std::to_string(seeds.size()) + " seeds; one seed per copy");
  checkWhich(which, "a reset");
  if (which.empty()) return;
  // the copies are one scene (checked when made): a state fits all or none
  envs_[which[0]]->checkState(state);
  forEachOf(which, [&](std::size_t i, std::size_t k) {
    envs_[i]->restoreChecked(state);
    envs_[i]->reseed(seeds[k]);
    findHotLines(i);
  });
  if (copy_waits_.empty()) return;
  const std::size_t robots = robot_names_.size();
  for (const std::size_t i : which) {
    std::fill_n(remaining_.begin() + static_cast<std::ptrdiff_t>(i * robots), robots, -1);
    copy_waits_[i] = 0;
  }
}

void VectorEnvironment::checkWhich(std::span<const std::size_t> which, const char* what) const {
  std::vector<bool> named(envs_.size(), false);
  for (const std::size_t i : which) {
    if (i >= envs_.size())
      throw ConfigError({},
                        std::string(what) + " names copy " + std::to_string(i) + " of " + std::to_string(envs_.size()));
    if (named[i]) throw ConfigError({}, std::string(what) + " names copy " + std::to_string(i) + " twice");
    named[i] = true;
  }
}

std::vector<Variable> VectorEnvironment::variables(std::size_t robot) const {
  if (robot >= robot_names_.size())
    throw std::out_of_range("ssx: robot " + std::to_string(robot) + " of a vector environment's " +
                            std::to_string(robot_names_.size()));
  return envs_[0]->variables(*artifacts_[robot]);
}

void VectorEnvironment::vary(std::span<const std::size_t> which, std::string_view name,
                             std::span<const double> values) {
  const std::size_t robots = robot_names_.size();
  if (values.size() != which.size() * robots)
    throw ConfigError({}, "varying '" + std::string(name) + "' in " + std::to_string(which.size()) + " copies needs " +
                              std::to_string(which.size()) + " x " + std::to_string(robots) + " values, got " +
                              std::to_string(values.size()));
  checkWhich(which, "varying constants");
  // every value checked before any copy changes (each robot's variable from copy 0: one scene)
  for (std::size_t r = 0; r < robots; ++r) {
    const std::vector<Variable> known = variables(r);
    const auto v = std::find_if(known.begin(), known.end(), [&](const Variable& x) { return name == x.name; });
    if (v == known.end()) {
      std::string list;
      for (const Variable& x : known) list += (list.empty() ? "" : ", ") + std::string(x.name);
      throw ConfigError({}, "robot '" + robot_names_[r] + "' has no constant '" + std::string(name) +
                                "' that can vary (it has: " + (list.empty() ? "none" : list) + ")");
    }
    for (std::size_t k = 0; k < which.size(); ++k) {
      const double x = values[k * robots + r];
      if (!std::isfinite(x) || x < v->min || x > v->max) {
        std::ostringstream m;
        m << "copy " << which[k] << ", robot '" << robot_names_[r] << "': " << name << " must be within [" << v->min
          << ", " << v->max << "] (" << v->doc << "), got " << x;
        throw ConfigError({}, m.str());
      }
    }
  }
  if (which.empty()) return;
  forEachOf(which, [&](std::size_t i, std::size_t k) {
    for (std::size_t r = 0; r < robots; ++r) envs_[i]->vary(*artifacts_[i * robots + r], name, values[k * robots + r]);
  });
}

void VectorEnvironment::checkOutput(std::span<const double> out, std::size_t width, const char* what) const {
  const std::size_t robots = robot_names_.size();
  if (out.size() != envs_.size() * robots * width)
    throw ConfigError({}, std::string(what) + " needs " + std::to_string(envs_.size()) + " x " +
                              std::to_string(robots) + " x " + std::to_string(width) + " numbers, got " +
                              std::to_string(out.size()));
}

void VectorEnvironment::readStates(std::size_t begin, std::size_t end, double* out) const {
  const std::size_t robots = robot_names_.size();
  for (std::size_t r = begin * robots; r < end * robots; ++r) {
    const BodyState& s = roots_[r]->state();
    const Vec3& x = s.pose.position;
    const Quat& q = s.pose.orientation;
    const Vec3& v = s.linear_velocity;
    const Vec3& w = s.angular_velocity;
    double* p = out + (r - begin * robots) * kRobotStateSize;
    p[0] = x.x(), p[1] = x.y(), p[2] = x.z();
    p[3] = q.w(), p[4] = q.x(), p[5] = q.y(), p[6] = q.z();
    p[7] = v.x(), p[8] = v.y(), p[9] = v.z();
    p[10] = w.x(), p[11] = w.y(), p[12] = w.z();
  }
}

void VectorEnvironment::robotStates(std::span<double> out) const {
  checkOutput(out, kRobotStateSize, "robotStates");
  // the copies in parallel: each robot's state is a few dependent loads into its own world
  const std::size_t robots = robot_names_.size();
  forChunks([&](std::size_t begin, std::size_t end) {
    readStates(begin, end, out.data() + begin * robots * kRobotStateSize);
  });
}

void VectorEnvironment::forChunks(Ref<std::size_t, std::size_t> fn) const {
  auto chunked = [&fn](std::size_t begin, std::size_t end) { fn(begin, end); };
  pool_->workers.parallelFor(envs_.size(), std::max<std::size_t>(1, envs_.size() / (pool_->workers.size() * 8)),
                             chunked);
}

void VectorEnvironment::checkImus() const {
  for (std::size_t r = 0; r < robot_names_.size(); ++r)
    if (imus_[r] == nullptr)
      throw ConfigError(
          {}, "robot '" + robot_names_[r] + "' has no IMU sensor to read (add <sensor plugin=\"imu\"/> to its type)");
}

void VectorEnvironment::readImu(std::size_t begin, std::size_t end, double* out) const {
  const std::size_t robots = robot_names_.size();
  for (std::size_t r = begin * robots; r < end * robots; ++r, out += 6) {
    const auto& m = static_cast<const ImuMeasurement&>(imus_[r]->latest());
    for (int k = 0; k < 3; ++k) out[k] = m.accelerometer[k], out[3 + k] = m.gyroscope[k];
  }
}

void VectorEnvironment::imuReadings(std::span<double> out) const {
  checkOutput(out, 6, "imuReadings");
  checkImus();
  readImu(0, envs_.size(), out.data());
}

void VectorEnvironment::moveRobots(std::span<const std::size_t> which, std::span<const double> offsets,
                                   std::span<const double> velocities) {
  const std::size_t robots = robot_names_.size();
  const std::size_t numbers = which.size() * robots * 3;
  if (offsets.size() != numbers || (!velocities.empty() && velocities.size() != numbers))
    throw ConfigError({}, "moving the robots of " + std::to_string(which.size()) + " copies needs " +
                              std::to_string(which.size()) + " x " + std::to_string(robots) +
                              " x 3 offsets (and velocities, when given)");
  for (const double x : offsets)
    if (!std::isfinite(x)) throw ConfigError({}, "a robot's offset holds a NaN or an infinity");
  for (const double x : velocities)
    if (!std::isfinite(x) || std::abs(x) > kMaxCommandValue)
      throw ConfigError({}, "a robot's start velocity is not finite or beyond 1e6 m/s");
  checkWhich(which, "moving robots");
  for (std::size_t k = 0; k < which.size(); ++k) {
    Environment& env = *envs_[which[k]];
    for (std::size_t r = 0; r < robots; ++r) {
      const std::size_t row = k * robots + r;
      const Vec3 offset(offsets[3 * row], offsets[3 * row + 1], offsets[3 * row + 2]);
      const Vec3 velocity = velocities.empty()
                                ? Vec3::Zero()
                                : Vec3(velocities[3 * row], velocities[3 * row + 1], velocities[3 * row + 2]);
      for (const int b : bodies_[which[k] * robots + r]) {
        BodyState s = env.bodyState(b);
        s.pose.position += offset;
        s.linear_velocity = velocity;
        s.angular_velocity = Vec3::Zero();
        env.setBodyState(b, s);
      }
    }
  }
}

void VectorEnvironment::setCommands(CommandLevel level, std::span<const double> values, std::size_t columns) {
  stageCommands(level, values, columns);
  // (the copies in parallel: a robot's driver is far in memory from the next one's; each thread
  // touches its own)
  forChunks([&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) deliverCommands(i);
  });
}

void VectorEnvironment::checkCommands(CommandLevel level, std::span<const double> values, std::size_t columns) {
  stageCommands(level, values, columns);
}

void VectorEnvironment::stageCommands(CommandLevel level, std::span<const double> values, std::size_t columns) {
  const std::size_t robots = robot_names_.size();
  const std::size_t rows = envs_.size() * robots;
  if (values.size() != rows * columns)
    throw ConfigError({}, "commands for a vector environment need " + std::to_string(envs_.size()) + " x " +
                              std::to_string(robots) + " rows of " + std::to_string(columns) + " numbers, got " +
                              std::to_string(values.size()) + " numbers");
  // every row checked before any robot gets one, the first problem by copy index reported; the
  // commands built here are what is sent
  staged_.resize(rows);
  problems_.resize(envs_.size());
  forChunks([&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      problems_[i].clear();
      for (std::size_t r = i * robots; r < (i + 1) * robots && problems_[i].empty(); ++r)
        problems_[i] = stageCommand(r, level, values.subspan(r * columns, columns));
    }
  });
  for (const std::string& problem : problems_)
    if (!problem.empty()) throw ConfigError({}, problem);
}

void VectorEnvironment::deliverCommands(std::size_t i) {
  const std::size_t robots = robot_names_.size();
  for (std::size_t r = i * robots; r < (i + 1) * robots; ++r) {
    if (delays_.empty() || delays_[r] == 0) {
      send(r, staged_[r]);
      continue;
    }
    if (remaining_[r] >= 0) send(r, waiting_[r]);  // overtaken: it takes effect now
    waiting_[r] = staged_[r];
    remaining_[r] = delays_[r];
    copy_waits_[i] = 1;
  }
}

std::string VectorEnvironment::stageCommand(std::size_t r, CommandLevel level, std::span<const double> row) {
  const std::size_t robots = robot_names_.size();
  auto who = [&] { return "copy " + std::to_string(r / robots) + ", robot '" + robot_names_[r % robots] + "'"; };
  const CommandInterface* target = commands_[r];  // (asked nothing: its answers are kept per robot)
  if (target == nullptr && level != CommandLevel::Position)
    return who() + " takes set-points only, no commands at the " + commandLevelName(level) + " level";
  const std::size_t robot = r % robots, rotors = rotor_counts_[robot];
  if (!Command::rowSizeFits(level, row.size(), rotors))
    return "a " + std::string(commandLevelName(level)) + " command for " + who() + " has " +
           Command::rowSizes(level, rotors) + " values, got " + std::to_string(row.size());
  for (const double x : row)
    if (!std::isfinite(x)) return "the command for " + who() + " holds a NaN or an infinity";
  if (level == CommandLevel::Rotors) {  // into the vector staged before: no allocation per step
    std::vector<double> speeds = std::move(staged_[r].rotor_speeds);
    speeds.assign(row.begin(), row.end());
    staged_[r] = Command::rotors(std::move(speeds));
  } else {
    staged_[r] = Command::fromRow(level, row);
  }
  const bool accepts = ((accepts_[robot] >> static_cast<unsigned>(level)) & 1u) != 0;
  const std::string why =
      target != nullptr ? CommandInterface::refusal(staged_[r], accepts, rotors) : staged_[r].problem();
  return why.empty() ? why : who() + ": " + why;
}

void VectorEnvironment::send(std::size_t r, const Command& command) {
  if (commands_[r] != nullptr)
    commands_[r]->setCommand(command);
  else
    setpoints_[r]->setSetpoint(command.setpoint);
}

}  // namespace ssx
