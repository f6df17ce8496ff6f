// ssx_bench_record: what recording costs. N quadrotors of the real-time study (ssx_rt_study: tau =
// 20 ms, 2 threads) fly into a formation in real time, with and without the recorder of --record
// (25 pose samples per simulated second, a saved state every 10 s), alternated RUNS times. Prints
// per run the median and p99 step time, the late steps (of them: those that took longer than a
// step, and those that began late after an on-time one; the rest followed a late one), the samples
// dropped and how long saved states took on the stepping thread (the first, and the longest of the
// later ones); then the file's size per robot and simulated second (all of it, and the saved states
// before compression) and the time to read every pose back (ssx::Recording, every sample decoded):
//   n=N run=K record=0|1 median_ms=... p99_ms=... late=... (long ..., began_late ...) dropped=...
//       state_ms_first=... state_ms_max=...
//   n=N bytes_per_robot_s=... (all, states compressed) states_raw=... read_s=... samples=... bodies=...
//       floats=...
// --fast runs unpaced (the stepper then waits for the writer: nothing is dropped). --keep FILE keeps
// the last recording there (read_numpy.py beside this program times reading it into numpy).
// --writer-nice K sets the writer thread's nice value (default 19, as RecordOptions has it).
// usage: ssx_bench_record [--n N] [--seconds S] [--runs R] [--fast] [--keep FILE] [--writer-nice K]
#include <ssx/ssx.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  int n = 10000, runs = 2;
  double seconds = 30;
  bool fast = false;
  std::string keep;
  int writer_nice = 19;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--fast") {
      fast = true;
      continue;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "usage: ssx_bench_record [--n N] [--seconds S] [--runs R] [--fast] [--keep FILE]\n");
      return 2;
    }
    if (a == "--keep") {
      keep = argv[++i];
      continue;
    }
    const double v = std::stod(argv[++i]);
    if (a == "--n") n = static_cast<int>(v);
    else if (a == "--writer-nice") writer_nice = static_cast<int>(v);
    else if (a == "--seconds") seconds = v;
    else if (a == "--runs") runs = static_cast<int>(v);
    else {
      std::fprintf(stderr, "usage: ssx_bench_record [--n N] [--seconds S] [--runs R] [--fast] [--keep FILE]\n");
      return 2;
    }
  }
  const fs::path file = fs::temp_directory_path() / ("ssx_bench_record_" + std::to_string(::getpid()) + ".mcap");
  // the real-time study's scene (ssx_rt_study, tau = 20 ms): a formation that takes off at 2 s and
  // flies into a sphere, so that the poses change as a flying swarm's do
  const double radius = std::max(1.5, 4.0 * std::sqrt(n / 70.0)), half = std::max(3.0, 1.6 * radius);
  char xml[2048];
  std::snprintf(xml, sizeof xml,
                "<scene><environment timestep=\"0.02\" seed=\"5\" threads=\"2\"/>"
                "<type name=\"q\" file=\"mk_quad_formation.xml\"/><ground/>"
                "<swarm type=\"q\" count=\"%d\" name=\"quad{i}\" layout=\"random\" min=\"%.3f %.3f 0.05\" "
                "max=\"%.3f %.3f 0.05\" min_distance=\"1.0\"><driver formation_index=\"{i}\" formation_size=\"%d\" "
                "formation_radius=\"%.3f\" formation_center=\"0 0 %.3f\" inner_rate_hz=\"50\" outer_rate_hz=\"50\" "
                "offset=\"0 0 1.5\" start_time=\"2\"/></swarm></scene>",
                n, -half, -half, half, half, n, radius, radius + 1.5);
  ssx::RecordSummary last;
  for (int run = 0; run < 2 * runs; ++run) {
    const bool record = run % 2 == 1;
    ssx::Scene scene = ssx::loadSceneFromString(xml, "bench_record.xml", std::string(SSX_EXAMPLES_DIR) + "/artifacts");
    ssx::Environment& env = *scene.environment;
    env.step(5);  // warm up
    std::unique_ptr<ssx::Recorder> recorder;
    if (record) {
      ssx::RecordOptions o;
      o.file = file;
      o.drop_when_behind = !fast;
      o.writer_nice = writer_nice;
      o.scene_xml = scene.model->toXml();
      recorder = std::make_unique<ssx::Recorder>(env, o);
    }
    env.timing().clear();
    ssx::RunOptions options;
    options.mode = fast ? ssx::RunOptions::Mode::Fast : ssx::RunOptions::Mode::RealTime;
    options.steps = static_cast<std::int64_t>(seconds / 0.02);
    const ssx::TimingSummary t = env.run(options);
    if (recorder) last = recorder->finish();
    std::printf(
        "n=%d run=%d record=%d median_ms=%.3f p99_ms=%.3f late=%lld (long %lld, began_late %lld) dropped=%lld "
        "state_ms_first=%.1f state_ms_max=%.1f\n",
        n, run / 2, record ? 1 : 0, t.median_ms, t.p99_ms, static_cast<long long>(t.overruns),
        static_cast<long long>(t.overruns_long), static_cast<long long>(t.overruns_began_late),
        static_cast<long long>(last.dropped * record), record ? last.state_ms_first : 0.0,
        record ? last.state_ms_max : 0.0);
    std::fflush(stdout);
  }
  // size: all of it (the saved states compressed in it), and the states' own size before compression
  const auto t0 = std::chrono::steady_clock::now();
  const ssx::Recording r(file);
  std::size_t floats = 0;
  for (std::size_t k = 0; k < r.times().size(); ++k) floats += r.positions(k).size() + r.orientations(k).size();
  const double read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::uint64_t state_bytes = 0;
  for (const ssx::Nanoseconds at : r.stateTimes()) state_bytes += r.stateAtOrBefore(at).size();
  const double robot_seconds = static_cast<double>(n) * last.simulated_s;
  std::printf(
      "n=%d bytes_per_robot_s=%.0f (all, states compressed) states_raw=%.0f read_s=%.2f samples=%zu bodies=%zu "
      "floats=%zu\n",
      n, static_cast<double>(last.bytes) / robot_seconds, static_cast<double>(state_bytes) / robot_seconds, read_s,
      r.times().size(), r.names().size(), floats);
  if (keep.empty()) {
    fs::remove(file);
  } else {
    fs::copy_file(file, keep, fs::copy_options::overwrite_existing);
    fs::remove(file);
    std::printf("kept %s\n", keep.c_str());
  }
  return 0;
}
