// Soak benchmark: the 70-quadrotor formation (examples/scenes/formation_sphere.xml without its
// cameras and log) run as fast as possible for 10^6 steps of 2 ms (33 minutes of simulated
// flight), printing the resident memory at 10^5 and 10^6 steps and its growth between them.
// Nothing in a step should allocate after warm-up (a test checks it), so the growth should be 0.
//
//   ssx_bench_soak [--steps N] [--threads T]
#include <ssx/ssx.hpp>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>

namespace {

// resident set size in KiB, from /proc/self/statm (pages)
long residentKiB() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

}  // namespace

int main(int argc, char** argv) {
  std::int64_t steps = 1'000'000;
  int threads = 2;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--steps") == 0) steps = std::atoll(argv[i + 1]);
    else if (std::strcmp(argv[i], "--threads") == 0) threads = std::atoi(argv[i + 1]);
  }
  ssx::SceneOptions options;
  options.threads = threads;
  // the demo scene without its cameras and its log: the simulation alone, no files
  const std::string dir = std::string(SSX_EXAMPLES_DIR) + "/scenes";
  std::ifstream in(dir + "/formation_sphere.xml");
  std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  xml = std::regex_replace(xml, std::regex("<render[^]*?</render>|<extension[^>]*/>"), "");
  ssx::Scene scene = ssx::loadSceneFromString(xml, "formation_sphere.xml", dir, options);
  ssx::Environment& env = *scene.environment;
  const std::int64_t first_mark = std::min<std::int64_t>(100'000, steps);
  env.step(first_mark);
  const long at_first = residentKiB();
  std::printf("steps=%lld rss_kib=%ld\n", static_cast<long long>(first_mark), at_first);
  std::fflush(stdout);
  env.step(steps - first_mark);
  const long at_end = residentKiB();
  std::printf("steps=%lld rss_kib=%ld\n", static_cast<long long>(steps), at_end);
  std::printf("growth_percent=%.3f (from step %lld to %lld; simulated %.0f s)\n",
              100.0 * static_cast<double>(at_end - at_first) / static_cast<double>(at_first),
              static_cast<long long>(first_mark), static_cast<long long>(steps), ssx::toSeconds(env.time()));
  env.stop();
  return 0;
}
