#pragma once
// Helpers for the rendering tests: small scenes from tests/data/valid/render, the osmesa engine alone,
// and pixel counts on the images it draws.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <png.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

namespace ssx::test {

inline const std::filesystem::path kRenderData = kData / "valid" / "render";

inline bool haveOsmesa() {
  const auto names = renderEngineNames();
  return std::find(names.begin(), names.end(), "osmesa") != names.end();
}

inline Scene loadRenderScene(const std::string& body) {
  return loadSceneFromString("<scene><environment timestep=\"0.002\" threads=\"2\"/>" + body + "</scene>",
                             "render.xml", kRenderData);
}

inline const CameraMeasurement& image(Environment& env, const std::string& artifact = "eye") {
  return dynamic_cast<const CameraMeasurement&>(env.findArtifact(artifact)->sensor(0).latest());
}

// centroid of the pixels with strong red and green and little blue (the yellow ball), or -1
inline double yellowRow(const Image& im) {
  double sum = 0, count = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const std::uint8_t* p = im.pixel(x, y);
      if (p[0] > 120 && p[1] > 100 && p[2] < 60) {
        sum += y;
        ++count;
      }
    }
  return count > 0 ? sum / count : -1;
}

// a PNG file read back as an RGB image (libpng's simplified API); empty when it cannot be read
inline Image readPng(const std::filesystem::path& file) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  Image im;
  if (png_image_begin_read_from_file(&png, file.c_str()) == 0) return im;
  png.format = PNG_FORMAT_RGB;
  std::vector<std::uint8_t> rgb(PNG_IMAGE_SIZE(png));
  if (png_image_finish_read(&png, nullptr, rgb.data(), 0, nullptr) == 0) return im;
  im.width = static_cast<int>(png.width);
  im.height = static_cast<int>(png.height);
  im.rgb = std::move(rgb);
  return im;
}

// the osmesa engine alone, outside any scene
inline std::unique_ptr<RenderEngine> osmesaEngine() {
  RenderSettings settings;
  settings.engine = "osmesa";
  return createRenderEngine(settings);
}

// the red pixels (however dimly lit) of an image, or of one of its columns: how many, mean red
struct Red {
  int count = 0;
  double mean = -1;
};
inline Red redPixels(const Image& im, int column = -1) {
  Red red;
  double sum = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      if (column >= 0 && x != column) continue;
      const std::uint8_t* p = im.pixel(x, y);
      if (p[0] > 30 && p[1] < 30 && p[2] < 30) {
        ++red.count;
        sum += p[0];
      }
    }
  if (red.count > 0) red.mean = sum / red.count;
  return red;
}

}  // namespace ssx::test
