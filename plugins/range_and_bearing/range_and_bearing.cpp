// range_and_bearing: situated communication between robots, as ARGoS's range-and-bearing sensor and
// actuator and the e-puck's and foot-bot's boards: every robot with one broadcasts its payload each
// time its sensor runs; each receives (ssx::RangeBearingMeasurement) the payload of every other
// robot within `range`, with the sender's range, bearing and elevation in its own frame. Messages
// are lost with probability `loss`; range and angles get Gaussian noise; with `occlusion`, a message
// passes only when a ray from the receiver to the sender meets the sender first (not a wall or
// another robot), with the physics engine's ray queries.
//
// A driver sets its robot's payload through ssx::RangeBearingInterface (found among its artifact's
// sensors by dynamic_cast); it is sent from the next sensors phase on.
//
// Parameters: kParameters below, or `ssx plugins --params range_and_bearing`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

namespace ssx::plugins {

class RangeAndBearing;

namespace {
// every range-and-bearing sensor of the environment, by artifact index (filled while they configure)
struct Directory {
  mutable std::vector<const RangeAndBearing*> by_artifact;
};
}  // namespace

class RangeAndBearing final : public SensorOf<RangeBearingMeasurement>, public RangeBearingInterface {
 public:
  static constexpr const char* kDoc = "messages between robots within range, with the sender's range, bearing and elevation";
  static constexpr ssx_plugin_param kParameters[] = {
      param::real("range", "0.8", "m", param::positive() & param::atMost(1e4), "how far messages reach"),
      param::integer("payload", "4", param::between(0, 65536), "bytes each robot sends"),
      param::text("data", "", "the payload sent until a driver sets one: bytes 0..255 separated by spaces (the rest 0); "
                              "a beacon without a driver (an item, a nest) sends it for good"),
      param::real("loss", "0", "", param::between(0, 1), "probability that a message is lost"),
      param::real("range_noise", "0", "m", param::nonNegative(), "standard deviation of the range received"),
      param::real("bearing_noise", "0", "rad", param::nonNegative(), "standard deviation of bearing and elevation"),
      param::flag("occlusion", "false", "a message passes only when nothing stands between the two robots"),
      param::real("height", "0", "m", param::between(-1000, 1000), "the board's height above the robot's origin"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    if (context.artifact->rootCount() == 0 || context.artifact->root().isStatic())
      throw params.error("a range_and_bearing sensor needs a dynamic root");
    (void)initialData(params);
  }

  // `data`: at most `payload` bytes, each 0..255
  static std::vector<std::uint8_t> initialData(const Descriptor& params) {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(params.get<std::int64_t>("payload")), 0);
    std::istringstream in(params.get<std::string>("data", ""));
    std::string word;
    for (std::size_t k = 0; in >> word; ++k) {
      char* end = nullptr;
      const long v = std::strtol(word.c_str(), &end, 10);
      if (*end != '\0' || v < 0 || v > 255) throw params.errorAt("data", "'" + word + "' is not a byte (0..255)");
      if (k >= out.size())
        throw params.errorAt("data", "more bytes than the payload holds (" + std::to_string(out.size()) + ")");
      out[k] = static_cast<std::uint8_t>(v);
    }
    return out;
  }

  void configure(const Descriptor& params, PluginSetup& setup) override {
    range_ = params.get<double>("range");
    data_ = initialData(params);
    loss_ = params.get<double>("loss");
    range_noise_ = params.get<double>("range_noise");
    bearing_noise_ = params.get<double>("bearing_noise");
    occlusion_ = params.get<bool>("occlusion");
    height_ = params.get<double>("height");
    directory_ = setup.shared<Directory>("range_and_bearing", [] { return Directory{}; });
    auto& all = directory_->by_artifact;
    const std::size_t me = artifact().index();
    if (all.size() <= me) all.resize(me + 1, nullptr);
    all[me] = this;
    setup.enableNeighborQueries(range_);
    if (occlusion_) setup.enableRayQueries();
  }

  // --- RangeBearingInterface ---
  void setData(std::span<const std::uint8_t> data) override {
    if (data.size() != data_.size())
      throw std::invalid_argument("range_and_bearing: a payload of " + std::to_string(data_.size()) + " bytes, got " +
                                  std::to_string(data.size()));
    std::copy(data.begin(), data.end(), data_.begin());
  }
  std::span<const std::uint8_t> data() const override { return data_; }

  void sense(const StepInfo& info) override {
    const Environment& env = environment();
    const Pose me = artifact().root().pose();
    const Vec3 at = me.transformPoint(Vec3(0, 0, height_));
    hits_.clear();
    env.neighbors(at, range_, hits_);  // ascending artifact order
    RangeBearingMeasurement& m = output();
    m.stamp = info.time;
    std::size_t kept = 0;
    for (const SpatialIndex::Hit& h : hits_) {
      const std::size_t j = h.id;
      if (j == artifact().index() || j >= directory_->by_artifact.size()) continue;
      const RangeAndBearing* sender = directory_->by_artifact[j];
      if (sender == nullptr) continue;
      const Pose other = sender->artifact().root().pose();
      const Vec3 to = other.transformPoint(Vec3(0, 0, sender->height_));
      const Vec3 relative = me.orientation.conjugate() * (to - at);
      const double distance = relative.norm();
      if (distance > range_) continue;
      if (loss_ > 0 && random().uniform() < loss_) continue;
      if (occlusion_ && occluded(at, to, sender->artifact())) continue;
      if (m.messages.size() <= kept) m.messages.emplace_back();
      RangeBearingMeasurement::Message& msg = m.messages[kept++];
      msg.sender = j;
      msg.range = distance + (range_noise_ > 0 ? random().normal(0.0, range_noise_) : 0.0);
      msg.bearing = std::atan2(relative.y(), relative.x());
      msg.elevation = std::atan2(relative.z(), std::hypot(relative.x(), relative.y()));
      if (bearing_noise_ > 0) {
        msg.bearing = std::remainder(msg.bearing + random().normal(0.0, bearing_noise_), 2 * M_PI);
        msg.elevation = std::clamp(msg.elevation + random().normal(0.0, bearing_noise_), -M_PI / 2, M_PI / 2);
      }
      msg.data.assign(sender->data_.begin(), sender->data_.end());
    }
    m.messages.resize(kept);
  }

  void saveState(StateWriter& out) const override {
    out.bytes(data_.data(), data_.size());
    const auto& m = static_cast<const RangeBearingMeasurement&>(latest());
    out.write(static_cast<std::uint64_t>(m.messages.size()));
    for (const auto& msg : m.messages) {
      out.write(static_cast<std::uint64_t>(msg.sender));
      out.write(msg.range);
      out.write(msg.bearing);
      out.write(msg.elevation);
      out.write(static_cast<std::uint64_t>(msg.data.size()));
      out.bytes(msg.data.data(), msg.data.size());
    }
  }
  void loadState(StateReader& in) override {
    in.bytes(data_.data(), data_.size());
    auto& m = output();
    m.messages.resize(in.count(8 * 5));
    for (auto& msg : m.messages) {
      msg.sender = static_cast<std::size_t>(in.get<std::uint64_t>());
      in.read(msg.range);
      in.read(msg.bearing);
      in.read(msg.elevation);
      msg.data.resize(in.count(1));
      in.bytes(msg.data.data(), msg.data.size());
    }
  }

 private:
  // whether a ray from here to the sender meets something else first
  bool occluded(const Vec3& from, const Vec3& to, const Artifact& sender) const {
    const Ray ray{from, to};
    RayHit hit;
    environment().castRays({&ray, 1}, {&hit, 1}, &artifact());
    if (!hit.hit) return false;
    for (std::size_t k = 0; k < sender.nodeCount(); ++k)
      if (sender.nodeAt(k).bodyIndex() == hit.body && hit.body >= 0) return false;
    return true;
  }

  double range_ = 0, loss_ = 0, range_noise_ = 0, bearing_noise_ = 0, height_ = 0;
  bool occlusion_ = false;
  std::vector<std::uint8_t> data_;
  std::shared_ptr<const Directory> directory_;
  std::vector<SpatialIndex::Hit> hits_;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::RangeAndBearing, "range_and_bearing"));
