#pragma once
/// @file
/// Measurement types shared between plugins: a sensor in one library and a driver in another
/// agree on these, and callbacks receive them without copies.

#include <ssx/export.hpp>
#include <ssx/plugin.hpp>
#include <ssx/render.hpp>
#include <ssx/state.hpp>
#include <ssx/types.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace ssx {

/// Simulated time, as a clock sensor reports it.
struct SSX_EXPORT ClockMeasurement : Measurement {
  std::int64_t step = 0;   ///< steps taken
  double seconds = 0.0;    ///< simulated time, s
  ~ClockMeasurement() override;
  bool finite() const noexcept override;
};

/// Pose and twist of a node, world frame, possibly with noise.
struct SSX_EXPORT PoseMeasurement : Measurement {
  Pose pose;                             ///< position (m) and orientation, world frame
  Vec3 linear_velocity = Vec3::Zero();   ///< m/s, world frame
  Vec3 angular_velocity = Vec3::Zero();  ///< rad/s, world frame
  ~PoseMeasurement() override;
  bool finite() const noexcept override;
};

/// An inertial measurement: specific force and angular rate in the IMU's frame, after bias, noise,
/// scale, quantisation and saturation; also as the raw integer counts a microcontroller reads.
struct SSX_EXPORT ImuMeasurement : Measurement {
  Vec3 accelerometer = Vec3::Zero();                   ///< specific force, m/s^2, IMU frame (reads +g upwards at rest)
  Vec3 gyroscope = Vec3::Zero();                       ///< angular rate, rad/s, IMU frame
  std::array<std::int32_t, 3> accelerometer_counts{};  ///< accelerometer / accelerometer_lsb
  std::array<std::int32_t, 3> gyroscope_counts{};      ///< gyroscope / gyroscope_lsb
  double accelerometer_lsb = 0.0;                      ///< m/s^2 per count
  double gyroscope_lsb = 0.0;                          ///< rad/s per count
  ~ImuMeasurement() override;
  bool finite() const noexcept override;
};

/// What a range sensor sees: other robots and obstacles within its range, nearest first.
struct SSX_EXPORT RangeMeasurement : Measurement {
  /// One robot or obstacle seen.
  struct Detection {
    Vec3 relative = Vec3::Zero();  ///< from the sensor to the robot (or the obstacle's nearest surface point), m
    double distance = 0.0;         ///< |relative| before noise, m
    std::size_t artifact = 0;      ///< index of the artifact seen
    bool obstacle = false;         ///< a static obstacle rather than a robot
  };
  bool body_frame = false;  ///< `relative` in the sensor's body frame, else the world frame
  std::vector<Detection> detections;  ///< nearest first
  ~RangeMeasurement() override;
  bool finite() const noexcept override;
};

/// What a ring of proximity (infrared) sensors reads: one reading per ray, 0 when nothing is within
/// range, larger when nearer (the sensor's response curve), with the distance each ray met.
struct SSX_EXPORT ProximityMeasurement : Measurement {
  std::vector<double> readings;   ///< per ray, in the sensor's order: 0..1
  std::vector<double> distances;  ///< per ray: m to what it met, +inf when nothing within range
  std::vector<double> angles;     ///< per ray: its direction, rad from the node's x axis toward y
  double range = 0.0;             ///< m: how far a ray reaches from the ring (the sensor's range)
  double radius = 0.0;            ///< m: the ring's distance from the node's z axis, where distances start
  ~ProximityMeasurement() override;
  bool finite() const noexcept override;
};

/// What ground sensors read: the floor's colour at each of their points, and its grey level.
struct SSX_EXPORT GroundMeasurement : Measurement {
  std::vector<Vec3> colors;       ///< per point: RGB 0..1
  std::vector<double> readings;   ///< per point: grey level, 0 black .. 1 white (with noise)
  ~GroundMeasurement() override;
  bool finite() const noexcept override;
};

/// What a range-and-bearing receiver got this step: one message per robot that sent one within range.
struct SSX_EXPORT RangeBearingMeasurement : Measurement {
  /// One message received.
  struct Message {
    std::size_t sender = 0;           ///< index of the sending artifact
    double range = 0.0;               ///< m, with noise
    double bearing = 0.0;             ///< rad, the sender's direction in the receiver's horizontal plane (0: ahead, positive: left)
    double elevation = 0.0;           ///< rad, above the receiver's horizontal plane
    std::vector<std::uint8_t> data;   ///< the payload the sender set
  };
  std::vector<Message> messages;  ///< in sender order
  ~RangeBearingMeasurement() override;
  bool finite() const noexcept override;
};

/// A range-and-bearing board's transmitter: what a driver sends to the robots around it. Implemented
/// by the range_and_bearing sensor; find it among an artifact's sensors with dynamic_cast.
class SSX_EXPORT RangeBearingInterface {
 public:
  virtual ~RangeBearingInterface();
  /// Sets the payload sent from the next sensors phase on (from the artifact's own driver, or
  /// between steps); its size is the sensor's `payload`. Throws std::invalid_argument for another size.
  virtual void setData(std::span<const std::uint8_t> data) = 0;
  /// The payload being sent.
  virtual std::span<const std::uint8_t> data() const = 0;
};

/// A camera image: RGB and, when asked for, depth (m along the optical axis), drawn from the
/// snapshot of the step it is stamped with.
struct SSX_EXPORT CameraMeasurement : Measurement {
  Image image;      ///< RGB (and depth when asked for), row 0 at the top
  CameraView view;  ///< the camera's pose (x forward, z up) and lens when it was drawn
  ~CameraMeasurement() override;
  bool finite() const noexcept override;
};

class Environment;

/// A measurement as a JSON object, as the recorder's `/ssx/sensors` channel and the viewer have it:
/// `{"kind":"imu","stamp":S,"accelerometer":[..],"gyroscope":[..]}` (sensor frame),
/// `{"kind":"pose",..,"position","orientation" (w x y z),"linear_velocity","angular_velocity"}`
/// (world frame) or `{"kind":"range",..,"frame":"body"|"world","detections":[{"seen":NAME,
/// "obstacle":B,"relative":[..],"distance":D}]}`; "" for kinds without one (clock, camera images).
/// `env` names the artifacts a range measurement saw.
SSX_EXPORT std::string measurementJson(const Measurement& m, const Environment& env);

/// Measurements into and out of a saved state (for sensors' and drivers' saveState / loadState).
inline void save(StateWriter& out, const ClockMeasurement& m) {
  out.write(m.stamp);
  out.write(m.step);
  out.write(m.seconds);
}
/// Reads what the matching save wrote.
inline void load(StateReader& in, ClockMeasurement& m) {
  in.read(m.stamp);
  in.read(m.step);
  in.read(m.seconds);
}
/// Writes a measurement (or a detection list) into a saved state.
inline void save(StateWriter& out, const PoseMeasurement& m) {
  out.write(m.stamp);
  out.write(m.pose);
  out.write(m.linear_velocity);
  out.write(m.angular_velocity);
}
/// Reads what the matching save wrote.
inline void load(StateReader& in, PoseMeasurement& m) {
  in.read(m.stamp);
  in.read(m.pose);
  in.read(m.linear_velocity);
  in.read(m.angular_velocity);
}
/// Writes a measurement (or a detection list) into a saved state.
inline void save(StateWriter& out, const ImuMeasurement& m) {
  out.write(m.stamp);
  out.write(m.accelerometer);
  out.write(m.gyroscope);
  out.write(m.accelerometer_counts);
  out.write(m.gyroscope_counts);
}
/// Reads what the matching save wrote.
inline void load(StateReader& in, ImuMeasurement& m) {
  in.read(m.stamp);
  in.read(m.accelerometer);
  in.read(m.gyroscope);
  in.read(m.accelerometer_counts);
  in.read(m.gyroscope_counts);
}
/// Writes a measurement (or a detection list) into a saved state.
inline void save(StateWriter& out, const std::vector<RangeMeasurement::Detection>& detections) {
  out.write(static_cast<std::uint64_t>(detections.size()));
  for (const auto& d : detections) {
    out.write(d.relative);
    out.write(d.distance);
    out.write(static_cast<std::uint64_t>(d.artifact));
    out.write(d.obstacle);
  }
}
/// Reads what the matching save wrote.
inline void load(StateReader& in, std::vector<RangeMeasurement::Detection>& detections) {
  detections.resize(in.count(8 * 3 + 8 + 8 + 1));
  for (auto& d : detections) {
    in.read(d.relative);
    in.read(d.distance);
    d.artifact = static_cast<std::size_t>(in.get<std::uint64_t>());
    in.read(d.obstacle);
  }
}
/// Writes a measurement (or a detection list) into a saved state.
inline void save(StateWriter& out, const RangeMeasurement& m) {
  out.write(m.stamp);
  save(out, m.detections);
}
/// Reads what the matching save wrote.
inline void load(StateReader& in, RangeMeasurement& m) {
  in.read(m.stamp);
  load(in, m.detections);
}

}  // namespace ssx
