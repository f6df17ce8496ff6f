// ssx_bench_render: what a 640 x 480 frame costs with N quadrotors in view (osmesa engine).
//
// For each N, a grid of mk_quad robots (three boxes each) on the ground, seen from above the
// grid's corner so that all are in view; the engine draws the posed render nodes of each step
// into an image (readback included, PNG encoding excluded). Prints the median and p95 over the
// frames, e.g.
//   n=1000 frames=100 width=640 height=480 median_ms=3.10 p95_ms=3.40
// The process is set up for llvmpipe as the ssx command sets itself up (LP_NUM_THREADS=0 unless set
// in the environment, glibc's trim threshold at 256 MiB; see cli/main.cpp), so the figures are what
// `ssx run --video` gets.
//
// --png DIR writes each N's last frame to DIR/render_N.png (to look at what the level of detail does).
// --shadows 1 draws the robots' shadows, as the scene cameras do (RenderSettings::shadows).
//
// usage: ssx_bench_render [--n N]... [--frames K] [--width W] [--height H] [--shadows 0|1] [--png DIR]
#include <ssx/ssx.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <memory>
#include <cstdio>
#include <malloc.h>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  std::vector<int> sizes;
  int frames = 100, width = 640, height = 480, shadows = 0;
  std::string png_dir;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--png") {
      png_dir = argv[i + 1];
      continue;
    }
    const int v = std::stoi(argv[i + 1]);
    if (a == "--n") sizes.push_back(v);
    else if (a == "--frames") frames = v;
    else if (a == "--width") width = v;
    else if (a == "--height") height = v;
    else if (a == "--shadows") shadows = v;
    else {
      std::fprintf(stderr, "usage: ssx_bench_render [--n N]... [--frames K] [--width W] [--height H] [--shadows 0|1] [--png DIR]\n");
      return 2;
    }
  }
  if (sizes.empty()) sizes = {70, 1000, 10000};
  setenv("LP_NUM_THREADS", "0", 0);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  for (int n : sizes) {
    try {
      char xml[1024];
      std::snprintf(xml, sizeof xml,
                    "<scene><environment timestep=\"0.002\" threads=\"1\"/>"
                    "<render engine=\"osmesa\" period=\"1\"/>"
                    "<ground/><type name=\"q\" file=\"mk_quad.xml\"/>"
                    "<swarm type=\"q\" count=\"%d\" name=\"q{i}\" spacing=\"1.0\" xyz=\"0 0 0.05\"/></scene>",
                    n);
      ssx::Scene scene = ssx::loadSceneFromString(xml, "bench_render.xml", std::string(SSX_EXAMPLES_DIR) + "/artifacts");
      ssx::Environment& env = *scene.environment;
      // the camera: above the grid's south-east corner, looking at its centre
      const double side = std::ceil(std::sqrt(static_cast<double>(n)));
      const ssx::Vec3 centre(side / 2, side / 2, 0);
      const double distance = 0.9 * side + 4.0;
      ssx::CameraView view;
      view.width = width;
      view.height = height;
      view.shadows = shadows != 0;
      view.pose.position = centre + distance * ssx::Vec3(0.62, -0.62, 0.48).normalized();
      const ssx::Vec3 forward = (centre - view.pose.position).normalized();
      const ssx::Vec3 left = ssx::Vec3::UnitZ().cross(forward).normalized();
      Eigen::Matrix3d r;
      r << forward, left, forward.cross(left);
      view.pose.orientation = ssx::Quat(r);
      ssx::RenderSettings settings;
      settings.engine = "osmesa";
      std::unique_ptr<ssx::RenderEngine> engine = ssx::createRenderEngine(settings);
      ssx::Image image;
      std::vector<double> ms;
      for (int f = 0; f <= frames; ++f) {
        env.step();
        const auto t0 = std::chrono::steady_clock::now();
        engine->renderView(view, env.renderNodes(), {0.6f, 0.7f, 0.85f, 1.0f}, image);
        const std::chrono::duration<double, std::milli> dt = std::chrono::steady_clock::now() - t0;
        if (f > 0) ms.push_back(dt.count());  // the first frame compiles the shaders
      }
      if (!png_dir.empty()) ssx::writePng(png_dir + "/render_" + std::to_string(n) + ".png", image);
      std::sort(ms.begin(), ms.end());
      std::printf("n=%d frames=%zu width=%d height=%d shadows=%d median_ms=%.2f p95_ms=%.2f\n", n, ms.size(), width, height, shadows,
                  ms[ms.size() / 2], ms[ms.size() * 95 / 100]);
      std::fflush(stdout);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "ssx_bench_render: n=%d: %s\n", n, e.what());
      return 1;
    }
  }
  return 0;
}
