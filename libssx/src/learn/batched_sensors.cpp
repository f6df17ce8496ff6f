// readSensors: one kind of sensor of many robots (of one environment, or of every copy of a
// VectorEnvironment) into one array (ssx/vector_environment.hpp lists the kinds and their
// layouts), their camera images, and every robot's contacts.
#include <ssx/error.hpp>
#include <ssx/measurements.hpp>
#include <ssx/odometry.hpp>
#include <ssx/vector_environment.hpp>

#include <algorithm>
#include <array>
#include <optional>
#include <string>

namespace ssx {

namespace {

enum class Kind { Pose, Imu, Proximity, Ground, Range, RangeBearing, Odometry };

constexpr std::array<std::pair<std::string_view, Kind>, 7> kKinds{{{"pose", Kind::Pose},
                                                                   {"imu", Kind::Imu},
                                                                   {"proximity", Kind::Proximity},
                                                                   {"ground", Kind::Ground},
                                                                   {"range", Kind::Range},
                                                                   {"range_and_bearing", Kind::RangeBearing},
                                                                   {"odometry", Kind::Odometry}}};

Kind kindOf(std::string_view name) {
  for (const auto& [n, k] : kKinds)
    if (n == name) return k;
  throw ConfigError({}, "no sensor kind '" + std::string(name) +
                            "' to read (pose, imu, proximity, ground, range, range_and_bearing or odometry)");
}

template <class M>
const M* firstOf(const Artifact& a) {
  for (std::size_t k = 0; k < a.sensorCount(); ++k)
    if (const auto* m = dynamic_cast<const M*>(&a.sensor(k).latest())) return m;
  return nullptr;
}

// the reading of `kind` of robot `a`, or nullptr when it has no such sensor (odometry: the driver)
const void* source(const Artifact& a, Kind kind) {
  switch (kind) {
    case Kind::Pose:
      return firstOf<PoseMeasurement>(a);
    case Kind::Imu:
      return firstOf<ImuMeasurement>(a);
    case Kind::Proximity:
      return firstOf<ProximityMeasurement>(a);
    case Kind::Ground:
      return firstOf<GroundMeasurement>(a);
    case Kind::Range:
      return firstOf<RangeMeasurement>(a);
    case Kind::RangeBearing:
      return firstOf<RangeBearingMeasurement>(a);
    case Kind::Odometry:
      return dynamic_cast<const OdometryInterface*>(a.driver());
  }
  return nullptr;
}

const char* toAdd(Kind kind) {
  switch (kind) {
    case Kind::Pose:
      return "add <sensor plugin=\"pose\"/> to its type";
    case Kind::Imu:
      return "add <sensor plugin=\"imu\"/> to its type";
    case Kind::Proximity:
      return "add <sensor plugin=\"proximity\"/> to its type";
    case Kind::Ground:
      return "add <sensor plugin=\"ground\"/> to its type";
    case Kind::Range:
      return "add <sensor plugin=\"range\"/> to its type";
    case Kind::RangeBearing:
      return "add <sensor plugin=\"range_and_bearing\"/> to its type";
    case Kind::Odometry:
      return "its driver keeps no odometry (diff_drive does)";
  }
  return "";
}

std::size_t countOf(const void* reading, Kind kind) {
  return kind == Kind::Proximity ? static_cast<const ProximityMeasurement*>(reading)->readings.size()
                                 : static_cast<const GroundMeasurement*>(reading)->readings.size();
}

}  // namespace

std::size_t sensorWidth(std::span<const Artifact* const> robots, std::string_view name, std::size_t slots) {
  const Kind kind = kindOf(name);
  std::optional<std::size_t> count;
  for (const Artifact* robot : robots) {
    const void* reading = source(*robot, kind);
    if (reading == nullptr)
      throw ConfigError({}, "robot '" + robot->name() + "' has no " + std::string(name) + " to read: " + toAdd(kind));
    if (kind != Kind::Proximity && kind != Kind::Ground) continue;
    const std::size_t n = countOf(reading, kind);
    if (n == 0)
      throw ConfigError({}, "robot '" + robot->name() + "''s " + std::string(name) +
                                " sensor has not measured yet: step the environments first");
    if (count && *count != n)
      throw ConfigError({}, "robot '" + robot->name() + "''s " + std::string(name) + " sensor has " +
                                std::to_string(n) + " values, robot '" + robots[0]->name() + "''s " +
                                std::to_string(*count) + ": one array needs the same number for every robot");
    count = n;
  }
  switch (kind) {
    case Kind::Pose:
      return 13;
    case Kind::Imu:
      return 6;
    case Kind::Odometry:
      return 9;
    case Kind::Range:
      return 5 * slots;
    case Kind::RangeBearing:
      return 4 * slots;
    case Kind::Proximity:
    case Kind::Ground:
      return count.value_or(0);
  }
  return 0;
}

std::size_t VectorEnvironment::sensorWidth(std::string_view name, std::size_t slots) const {
  // copy 0's robots say it for all (every copy is the same scene)
  return ssx::sensorWidth(std::span(artifacts_).first(robot_names_.size()), name, slots);
}

void VectorEnvironment::readSensors(std::string_view name, std::span<double> out, std::size_t slots) const {
  const std::size_t width = sensorWidth(name, slots), robots = robot_names_.size();
  if (out.size() != envs_.size() * robots * width)
    throw ConfigError({}, "reading " + std::string(name) + " needs " + std::to_string(envs_.size()) + " x " +
                              std::to_string(robots) + " x " + std::to_string(width) + " numbers, got " +
                              std::to_string(out.size()));
  ssx::readSensors(artifacts_, name, out, slots, robots);
}

void readSensors(std::span<const Artifact* const> robots, std::string_view name, std::span<double> out,
                 std::size_t slots, std::size_t per_copy) {
  const Kind kind = kindOf(name);
  if (per_copy == 0) per_copy = robots.size();
  const std::size_t width = sensorWidth(robots.first(std::min(per_copy, robots.size())), name, slots);
  if (out.size() != robots.size() * width)
    throw ConfigError({}, "reading " + std::string(name) + " of " + std::to_string(robots.size()) + " robots needs " +
                              std::to_string(robots.size()) + " x " + std::to_string(width) + " numbers, got " +
                              std::to_string(out.size()));
  auto who = [&](std::size_t row) {
    const std::string robot = "robot '" + robots[row]->name() + "'";
    return per_copy == robots.size() ? robot : "copy " + std::to_string(row / per_copy) + ", " + robot;
  };
  for (std::size_t row = 0; row < robots.size(); ++row) {
    double* p = out.data() + row * width;
    const void* reading = source(*robots[row], kind);
    if (reading == nullptr)  // (another copy's robot: the same scene, so the same sensors)
      throw ConfigError({}, who(row) + " has no " + std::string(name) + " to read: " + toAdd(kind));
    switch (kind) {
      case Kind::Pose: {
        const auto& m = *static_cast<const PoseMeasurement*>(reading);
        const Quat& q = m.pose.orientation;
        const double v[13] = {m.pose.position.x(),
                              m.pose.position.y(),
                              m.pose.position.z(),
                              q.w(),
                              q.x(),
                              q.y(),
                              q.z(),
                              m.linear_velocity.x(),
                              m.linear_velocity.y(),
                              m.linear_velocity.z(),
                              m.angular_velocity.x(),
                              m.angular_velocity.y(),
                              m.angular_velocity.z()};
        std::copy(v, v + 13, p);
        break;
      }
      case Kind::Imu: {
        const auto& m = *static_cast<const ImuMeasurement*>(reading);
        for (int k = 0; k < 3; ++k) p[k] = m.accelerometer[k], p[3 + k] = m.gyroscope[k];
        break;
      }
      case Kind::Proximity:
      case Kind::Ground: {
        const auto& values = kind == Kind::Proximity ? static_cast<const ProximityMeasurement*>(reading)->readings
                                                     : static_cast<const GroundMeasurement*>(reading)->readings;
        if (values.size() != width)
          throw ConfigError({}, who(row) + ": " + std::to_string(values.size()) + " " + std::string(name) +
                                    " values, not " + std::to_string(width));
        std::copy(values.begin(), values.end(), p);
        break;
      }
      case Kind::Range: {
        const auto& d = static_cast<const RangeMeasurement*>(reading)->detections;
        std::fill(p, p + width, 0.0);
        for (std::size_t k = 0; k < std::min(slots, d.size()); ++k) {
          const double v[5] = {1.0, d[k].relative.x(), d[k].relative.y(), d[k].relative.z(), d[k].distance};
          std::copy(v, v + 5, p + 5 * k);
        }
        break;
      }
      case Kind::RangeBearing: {
        const auto& msgs = static_cast<const RangeBearingMeasurement*>(reading)->messages;
        std::fill(p, p + width, 0.0);
        for (std::size_t k = 0; k < std::min(slots, msgs.size()); ++k) {
          const double v[4] = {1.0, msgs[k].range, msgs[k].bearing, msgs[k].elevation};
          std::copy(v, v + 4, p + 4 * k);
        }
        break;
      }
      case Kind::Odometry: {
        const Odometry o = static_cast<const OdometryInterface*>(reading)->odometry();
        const double v[9] = {o.x,          o.y,           o.yaw,        o.forward,    o.yaw_rate,
                             o.left_speed, o.right_speed, o.left_angle, o.right_angle};
        std::copy(v, v + 9, p);
        break;
      }
    }
  }
}

std::array<std::size_t, 2> VectorEnvironment::imageSize() const {
  return ssx::imageSize(std::span(artifacts_).first(robot_names_.size()));
}

std::array<std::size_t, 2> imageSize(std::span<const Artifact* const> robots) {
  std::array<std::size_t, 2> size{0, 0};
  for (std::size_t r = 0; r < robots.size(); ++r) {
    const std::string& name = robots[r]->name();
    const CameraMeasurement* m = firstOf<CameraMeasurement>(*robots[r]);
    if (m == nullptr)
      throw ConfigError({}, "robot '" + name +
                                "' has no camera to read: add <sensor plugin=\"camera\"/> to its type (and a render "
                                "engine that draws pixels, <render engine=\"osmesa\"/>)");
    const std::array<std::size_t, 2> own{static_cast<std::size_t>(m->image.height),
                                         static_cast<std::size_t>(m->image.width)};
    if (m->image.rgb.empty() || own[0] * own[1] * 3 != m->image.rgb.size())
      throw ConfigError({}, "robot '" + name + "''s camera has not drawn yet: step the environments first");
    if (r > 0 && own != size)
      throw ConfigError({}, "robot '" + name + "''s camera draws " + std::to_string(own[1]) + " x " +
                                std::to_string(own[0]) + " pixels, robot '" + robots[0]->name() + "''s " +
                                std::to_string(size[1]) + " x " + std::to_string(size[0]) +
                                ": one array needs the same size for every robot");
    size = own;
  }
  return size;
}

void VectorEnvironment::cameraImages(std::span<std::uint8_t> out) const {
  const std::array<std::size_t, 2> size = imageSize();
  const std::size_t bytes = size[0] * size[1] * 3, robots = robot_names_.size();
  if (out.size() != envs_.size() * robots * bytes)
    throw ConfigError({}, "camera images need " + std::to_string(envs_.size()) + " x " + std::to_string(robots) +
                              " x " + std::to_string(size[0]) + " x " + std::to_string(size[1]) + " x 3 bytes, got " +
                              std::to_string(out.size()));
  // every copy is the same scene: a camera of another copy has drawn the same size, or nothing
  // yet (the copies left out of the steps since the start); the first such is reported
  std::vector<std::string>& problems = problems_;
  problems.assign(envs_.size(), {});
  auto copy = [&](std::size_t begin, std::size_t end) {
    for (std::size_t row = begin * robots; row < end * robots; ++row) {
      const Image& image = firstOf<CameraMeasurement>(*artifacts_[row])->image;
      if (image.rgb.size() != bytes) {
        problems[row / robots] = "copy " + std::to_string(row / robots) + ", robot '" + robot_names_[row % robots] +
                                 "': its camera has not drawn yet (step this copy first)";
        continue;
      }
      std::copy(image.rgb.begin(), image.rgb.end(), out.begin() + static_cast<std::ptrdiff_t>(row * bytes));
    }
  };
  forChunks(copy);
  for (const std::string& problem : problems)
    if (!problem.empty()) throw ConfigError({}, problem);
}

void cameraImages(std::span<const Artifact* const> robots, std::span<std::uint8_t> out) {
  const std::array<std::size_t, 2> size = imageSize(robots);
  const std::size_t bytes = size[0] * size[1] * 3;
  if (out.size() != robots.size() * bytes)
    throw ConfigError({}, "camera images of " + std::to_string(robots.size()) + " robots need " +
                              std::to_string(robots.size()) + " x " + std::to_string(size[0]) + " x " +
                              std::to_string(size[1]) + " x 3 bytes, got " + std::to_string(out.size()));
  for (std::size_t r = 0; r < robots.size(); ++r) {
    const Image& image = firstOf<CameraMeasurement>(*robots[r])->image;
    std::copy(image.rgb.begin(), image.rgb.end(), out.begin() + static_cast<std::ptrdiff_t>(r * bytes));
  }
}

}  // namespace ssx

namespace ssx {

void VectorEnvironment::recordContacts(bool on) {
  forEach([&](std::size_t i) { envs_[i]->recordContacts(on); });
}

void VectorEnvironment::contactImpulses(std::span<double> out) const {
  const std::size_t robots = robot_names_.size();
  if (out.size() != envs_.size() * robots * 2)
    throw ConfigError({}, "contactImpulses needs " + std::to_string(envs_.size()) + " x " + std::to_string(robots) +
                              " x 2 numbers, got " + std::to_string(out.size()));
  std::fill(out.begin(), out.end(), 0.0);
  for (std::size_t i = 0; i < envs_.size(); ++i) {
    double* copy = out.data() + i * robots * 2;
    for (const EngineContact& c : envs_[i]->contacts()) {
      const int a = robot_of_body_[static_cast<std::size_t>(c.body_a)];
      const int b = c.body_b >= 0 ? robot_of_body_[static_cast<std::size_t>(c.body_b)] : -1;
      if (c.body_b < 0) {
        if (a >= 0) copy[2 * a] += c.impulse;
        continue;
      }
      if (a >= 0) copy[2 * a + 1] += c.impulse;
      if (b >= 0) copy[2 * b + 1] += c.impulse;
    }
  }
}

}  // namespace ssx
