// ground: the floor's colour under a robot (ssx::GroundMeasurement), as an e-puck's or foot-bot's
// ground sensors read it: at each of `points` (x y in the node's frame, projected straight down),
// the colour of the floor there and its grey level (0 black .. 1 white, ITU-R 601 luma). The floor
// is `floor` (a colour), then `image` (a PNG file, relative to the file the attribute is written
// in) laid over `image_area` "X0 Y0 X1 Y1" (m, world: the image's top row along y = Y1, its left
// column along x = X0, as a map seen from above; nearest pixel; a pixel's alpha mixes it with the
// floor's colour), then `regions`, later ones over earlier ones:
//   circle CX CY R  RED GREEN BLUE      a disc of radius R (m) centred at (CX, CY)
//   rect X0 Y0 X1 Y1  RED GREEN BLUE    an axis-aligned rectangle
// separated by ';', colours 0..1, world frame. `noise` adds Gaussian noise to each grey level,
// kept within [0, 1]. A swarm's sensors share one copy of an image.
//
// Parameters: kParameters below, or `ssx plugins --params ground`.
#include <ssx/artifact.hpp>
#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>
#include <ssx/plugin_abi.hpp>

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace ssx::plugins {

namespace {

struct Region {
  bool circle = true;
  double a = 0, b = 0, c = 0, d = 0;  // circle: cx, cy, r; rect: x0, y0, x1, y1
  Vec3 color = Vec3::Zero();
  bool contains(double x, double y) const {
    if (circle) return (x - a) * (x - a) + (y - b) * (y - b) <= c * c;
    return x >= std::min(a, c) && x <= std::max(a, c) && y >= std::min(b, d) && y <= std::max(b, d);
  }
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\n\r");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\n\r") - b + 1);
}

// calls read(item) for each non-empty item of a ';'-separated list, until one returns false
template <class Read>
void forEachItem(const std::string& text, Read&& read) {
  std::stringstream all(text);
  std::string item;
  while (std::getline(all, item, ';')) {
    item = trim(item);
    if (!item.empty() && !read(item)) return;
  }
}

// the regions as written, or a message saying what is wrong with the first that is not right
std::vector<Region> parseRegions(const std::string& text, std::string& error) {
  std::vector<Region> out;
  forEachItem(text, [&](const std::string& item) {
    std::istringstream in(item);
    std::string kind;
    in >> kind;
    Region r;
    r.circle = kind == "circle";
    if (kind != "circle" && kind != "rect") {
      error = "a region is 'circle CX CY R RED GREEN BLUE' or 'rect X0 Y0 X1 Y1 RED GREEN BLUE', got '" + item + "'";
      return false;
    }
    double v[7];
    const int n = r.circle ? 6 : 7;
    for (int k = 0; k < n; ++k) in >> v[k];
    std::string rest;
    if (in.fail() || (in >> rest)) {
      error = "region '" + item + "' needs " + std::to_string(n) + " numbers after '" + kind + "'";
      return false;
    }
    r.a = v[0];
    r.b = v[1];
    r.c = v[2];
    if (!r.circle) r.d = v[3];
    r.color = Vec3(v[n - 3], v[n - 2], v[n - 1]);
    if (!(r.color.array() >= 0).all() || !(r.color.array() <= 1).all() || (r.circle && !(r.c > 0))) {
      error = "region '" + item + "': colours are within 0..1 and a circle's radius is positive";
      return false;
    }
    out.push_back(r);
    return true;
  });
  if (!error.empty()) out.clear();
  return out;
}

// a floor image, decoded to 8-bit RGBA rows (top row first)
struct FloorImage {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
};

constexpr std::uint32_t kMaxImageSide = 16384;  // pixels: at most 1 GiB decoded

// throws Error saying what is wrong (a directory or FIFO is refused before it is opened)
FloorImage loadImage(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw Error("'" + file.string() + "' is not a file");
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  auto failed = [&](const std::string& what) {
    const std::string message = "'" + file.string() + "': " + what;
    png_image_free(&image);
    return Error(message);
  };
  if (!png_image_begin_read_from_file(&image, file.c_str())) throw failed(std::string("not a PNG image (") + image.message + ")");
  if (image.width > kMaxImageSide || image.height > kMaxImageSide)
    throw failed(std::to_string(image.width) + " x " + std::to_string(image.height) + " pixels, more than " +
                 std::to_string(kMaxImageSide) + " on a side");
  image.format = PNG_FORMAT_RGBA;
  FloorImage out;
  out.width = image.width;
  out.height = image.height;
  out.rgba.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgba.data(), 0, nullptr)) throw failed(image.message);
  png_image_free(&image);
  return out;
}

// `image` as written, resolved against the directory of the file it was written in
std::filesystem::path imagePath(const Descriptor& params) {
  const Descriptor::Attribute* a = params.find("image");
  const std::filesystem::path file = a->value;
  if (file.is_absolute() || a->where.file.empty()) return file;
  return std::filesystem::path(a->where.file).parent_path() / file;
}

// "X0 Y0 X1 Y1" with X1 > X0 and Y1 > Y0, or a message
bool parseArea(const std::string& text, double area[4], std::string& error) {
  std::istringstream in(text);
  std::string rest;
  for (int k = 0; k < 4; ++k) in >> area[k];
  if (in.fail() || (in >> rest) || !(area[2] > area[0]) || !(area[3] > area[1]) || !std::isfinite(area[2] - area[0]) ||
      !std::isfinite(area[3] - area[1])) {
    error = "the image's area is 'X0 Y0 X1 Y1' (m, world) with X1 > X0 and Y1 > Y0, got '" + text + "'";
    return false;
  }
  return true;
}

std::vector<Vec3> parsePoints(const std::string& text, std::string& error) {
  std::vector<Vec3> out;
  forEachItem(text, [&](const std::string& item) {
    std::istringstream in(item);
    double x = 0, y = 0;
    std::string rest;
    in >> x >> y;
    if (in.fail() || (in >> rest)) {
      error = "a point is 'X Y' (m, in the node's frame), got '" + item + "'";
      return false;
    }
    out.push_back(Vec3(x, y, 0));
    return true;
  });
  if (!error.empty()) out.clear();
  if (out.empty() && error.empty()) error = "give at least one point";
  return out;
}

}  // namespace

class GroundSensor final : public SensorOf<GroundMeasurement> {
 public:
  static constexpr const char* kDoc = "the floor's colour under the robot, from a floor image and colour regions of the scene";
  static constexpr ssx_plugin_param kParameters[] = {
      param::text("points", "0 0", "where it looks, 'X Y' in the node's frame (m), separated by ';'"),
      param::vec3("floor", "1 1 1", "", param::between(0, 1), "the floor's colour where no region is (RGB 0..1)"),
      param::text("image", "", "a PNG image of the floor (relative to the file this is written in), laid over image_area"),
      param::text("image_area", "", "where the image lies: 'X0 Y0 X1 Y1' (m, world; its top row along y = Y1)"),
      param::text("regions", "", "'circle CX CY R RED GREEN BLUE' or 'rect X0 Y0 X1 Y1 RED GREEN BLUE' (m, world), ';' between"),
      param::real("noise", "0", "", param::between(0, 1), "standard deviation of each grey level"),
      param::text("node", "", "physic node it is fixed to (default: the first root)"),
  };

  static void validate(const Descriptor& params, const PluginContext& context) {
    std::string error;
    (void)parsePoints(params.get<std::string>("points"), error);
    if (!error.empty()) throw params.errorAt("points", error);
    (void)parseRegions(params.get<std::string>("regions", ""), error);
    if (!error.empty()) throw params.errorAt("regions", error);
    const bool image = !params.get<std::string>("image", "").empty(), area = !params.get<std::string>("image_area", "").empty();
    if (image != area) throw params.errorAt(image ? "image" : "image_area", "image and image_area go together");
    if (image) {
      double corners[4];
      if (!parseArea(params.get<std::string>("image_area"), corners, error)) throw params.errorAt("image_area", error);
      try {
        const std::filesystem::path file = imagePath(params);
        (void)context.shared<FloorImage>(file.string(), [&] { return loadImage(file); });
      } catch (const Error& e) {
        throw params.errorAt("image", std::string(e.what()) + " (a PNG file, relative to the file this is written in)");
      }
    }
    (void)context.artifact->nodeFromParameter(params, "node");
  }

  void configure(const Descriptor& params, PluginSetup& setup) override {
    std::string error;
    points_ = parsePoints(params.get<std::string>("points"), error);
    regions_ = parseRegions(params.get<std::string>("regions", ""), error);
    if (!params.get<std::string>("image", "").empty()) {
      (void)parseArea(params.get<std::string>("image_area"), area_, error);
      const std::filesystem::path file = imagePath(params);
      image_ = setup.shared<FloorImage>(file.string(), [&] { return loadImage(file); });
    }
    floor_ = params.get<Vec3>("floor");
    noise_ = params.get<double>("noise");
    node_ = &artifact().nodeFromParameter(params, "node");
    output().colors.assign(points_.size(), Vec3::Zero());
    output().readings.assign(points_.size(), 0.0);
  }

  void sense(const StepInfo& info) override {
    const Pose pose = node_->pose();
    GroundMeasurement& m = output();
    m.stamp = info.time;
    for (std::size_t k = 0; k < points_.size(); ++k) {
      const Vec3 p = pose.transformPoint(points_[k]);
      Vec3 color = floor_;
      if (image_ != nullptr) color = imageColor(p.x(), p.y(), color);
      for (const Region& r : regions_)
        if (r.contains(p.x(), p.y())) color = r.color;
      m.colors[k] = color;
      double grey = 0.299 * color.x() + 0.587 * color.y() + 0.114 * color.z();
      if (noise_ > 0) grey += random().normal(0.0, noise_);
      m.readings[k] = std::clamp(grey, 0.0, 1.0);
    }
  }

  void saveState(StateWriter& out) const override {
    const auto& m = static_cast<const GroundMeasurement&>(latest());
    for (std::size_t k = 0; k < points_.size(); ++k) {
      out.write(m.colors[k]);
      out.write(m.readings[k]);
    }
  }
  void loadState(StateReader& in) override {
    GroundMeasurement& m = output();
    for (std::size_t k = 0; k < points_.size(); ++k) {
      in.read(m.colors[k]);
      in.read(m.readings[k]);
    }
  }

 private:
  // the image's nearest pixel at (x, y) over `under`, or `under` outside its area
  Vec3 imageColor(double x, double y, const Vec3& under) const {
    if (!(x >= area_[0] && x <= area_[2] && y >= area_[1] && y <= area_[3])) return under;
    const auto pixel = [](double u, std::uint32_t n) {
      return std::min(static_cast<std::uint32_t>(u * n), n - 1);  // (u in [0, 1]; its right and top edges: the last pixel)
    };
    const std::uint32_t column = pixel((x - area_[0]) / (area_[2] - area_[0]), image_->width);
    const std::uint32_t row = pixel((area_[3] - y) / (area_[3] - area_[1]), image_->height);
    const std::uint8_t* p = image_->rgba.data() + (static_cast<std::size_t>(row) * image_->width + column) * 4;
    const double alpha = p[3] / 255.0;
    return alpha * Vec3(p[0], p[1], p[2]) / 255.0 + (1 - alpha) * under;
  }

  std::vector<Vec3> points_;
  std::vector<Region> regions_;
  std::shared_ptr<const FloorImage> image_;
  double area_[4] = {0, 0, 0, 0};
  Vec3 floor_ = Vec3::Ones();
  double noise_ = 0;
  const PhysicNode* node_ = nullptr;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_SENSOR(ssx::plugins::GroundSensor, "ground"));
