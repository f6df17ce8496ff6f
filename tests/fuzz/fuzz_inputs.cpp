// What the fuzz targets do with one input (see fuzz_inputs.hpp).
#include "fuzz_inputs.hpp"

#include "command_line.hpp"
#include "record/mcap_reader.hpp"
#include "record/pose_codec.hpp"

#include <ssx/ssx.hpp>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace ssx::fuzz {

namespace {

namespace fs = std::filesystem;

const fs::path kExamples = SSX_EXAMPLES_DIR;
const fs::path kFuzzDir = SSX_FUZZ_DIR;

// one scratch directory per process for the files an input names
const fs::path& scratch() {
  static const fs::path dir = [] {
    std::string pattern = (fs::temp_directory_path() / "ssx_fuzz_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    return fs::path(pattern);
  }();
  return dir;
}

std::string_view text(std::span<const std::uint8_t> data) {
  return {reinterpret_cast<const char*>(data.data()), data.size()};
}

void write(const fs::path& file, std::string_view content) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
}

SceneOptions options() {
  SceneOptions o;
  o.search_installed_plugins = true;  // the built-in plugins beside this libssx
  o.threads = 1;
  return o;
}

// an attribute value as XML text
std::string escape(std::string_view value) {
  std::string out;
  for (const char c : value) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '"': out += "&quot;"; break;
      case '\0': break;  // not XML
      default: out += c;
    }
  }
  return out;
}

// An ODE internal error is a finding too: after one, ODE cannot be torn down (the world is
// leaked on purpose) and every later environment in the process leaks as well, so the input that
// caused it is reported here rather than a later one by LeakSanitizer.
void expected(const Error& e) {
  if (std::string_view(e.what()).find("ode internal error") != std::string_view::npos) {
    std::fprintf(stderr, "fuzz: ODE failed inside its step: %s\n", e.what());
    std::abort();
  }
}

// loads, then steps: the expected ways to refuse are SceneError and ssx::Error
void loadAndStep(const std::string& xml, const fs::path& base, std::int64_t steps) {
  Scene scene;
  try {
    scene = loadSceneFromString(xml, "fuzz.xml", base, options());
  } catch (const SceneError&) {
    return;
  }
  try {
    scene.environment->step(steps);
    scene.environment->stop();
  } catch (const Error& e) {
    expected(e);
  }
}

}  // namespace

void sceneInput(std::span<const std::uint8_t> data) {
  const std::string_view input = text(data);
  const auto split = input.find("\n----\n");
  write(scratch() / "a.xml", split == std::string_view::npos ? std::string_view() : input.substr(split + 6));
  try {
    (void)loadSceneFromString(input.substr(0, split), "fuzz.xml", scratch(), options());
  } catch (const SceneError&) {
  }
}

void artifactInput(std::span<const std::uint8_t> data) {
  write(scratch() / "a.xml", text(data));
  loadAndStep(R"(<scene><environment timestep="0.002"/><ground/><type name="a" file="a.xml"/>
      <swarm type="a" count="3" name="a{i}" layout="grid" spacing="1" xyz="0 0 0.5"/></scene>)",
              scratch(), 25);
}

void robotInput(std::span<const std::uint8_t> data) {
  write(scratch() / "a.urdf", text(data));
  loadAndStep(R"(<scene><environment timestep="0.002"/><ground/><type name="a" file="a.urdf"/>
      <swarm type="a" count="2" name="a{i}" layout="grid" spacing="2" xyz="0 0 0.5" allow_overlap="true"/></scene>)",
              scratch(), 25);
}

void parameterInput(std::span<const std::uint8_t> data) {
  // the plugins of an mk_quad, their declared parameters read from the classes themselves
  struct Target {
    const char* element;  // how the scene addresses it
    const char* plugin;
    PluginKind kind;
  };
  static const Target targets[] = {{"driver", "quadrotor", PluginKind::Driver},
                                   {"sensor index=\"0\"", "imu", PluginKind::Sensor},
                                   {"sensor index=\"1\"", "pose", PluginKind::Sensor}};
  static const std::vector<std::vector<std::string>> names = [] {
    ClassLoader loader;
    loader.addSearchDirectory(ClassLoader::installedPluginDirectory());
    std::vector<std::vector<std::string>> out;
    for (const auto& t : targets) {
      const ssx_plugin_class& c = loader.classInfo(t.plugin, t.plugin, t.kind);
      std::vector<std::string> params;
      for (std::uint32_t i = 0; i < c.param_count; ++i) params.emplace_back(c.params[i].name);
      out.push_back(std::move(params));
    }
    return out;
  }();
  std::string attributes[3];
  std::string_view input = text(data);
  for (int line = 0; line < 4 && input.size() >= 2; ++line) {
    const auto end = input.find('\n');
    const std::string_view item = input.substr(0, end);
    input = end == std::string_view::npos ? std::string_view() : input.substr(end + 1);
    if (item.size() < 2) continue;
    const std::size_t t = static_cast<unsigned char>(item[0]) % 3;
    if (names[t].empty()) continue;
    const std::string& name = names[t][static_cast<unsigned char>(item[1]) % names[t].size()];
    attributes[t] += " " + name + "=\"" + escape(item.substr(2)) + "\"";
  }
  std::string xml = R"(<scene><environment timestep="0.001"/><ground/><type name="q" file=")" +
                    (kExamples / "artifacts" / "mk_quad.xml").string() +
                    R"("/><artifact name="q0" type="q" xyz="0 0 0.3">)";
  for (int t = 0; t < 3; ++t)
    if (!attributes[t].empty()) xml += std::string("<") + targets[t].element + attributes[t] + "/>";
  xml += "</artifact></scene>";
  loadAndStep(xml, scratch(), 200);
}

void stateInput(std::span<const std::uint8_t> data) {
  // one environment per process, rewound to its saved state before every input
  struct World {
    Scene scene;
    std::vector<std::byte> start;
  };
  static World* world = [] {
    auto* w = new World;
    w->scene = loadScene(kFuzzDir / "state_scene.xml", options());
    w->scene.environment->step(50);
    w->start = w->scene.environment->saveState();
    return w;
  }();
  Environment& env = *world->scene.environment;
  if (env.state() != Environment::State::Running) {  // an earlier input made it fail: start again
    world->scene = loadScene(kFuzzDir / "state_scene.xml", options());
    world->scene.environment->step(50);
  }
  Environment& e = *world->scene.environment;
  e.restoreState(world->start);

  std::vector<std::byte> buffer(data.size());
  if (!data.empty()) std::memcpy(buffer.data(), data.data(), data.size());
  if (text(data).substr(0, 8) != "SSXSTATE") {
    // a payload: give it the header of a state of this scene, with its size and checksum
    constexpr std::size_t kHeader = 40;
    std::vector<std::byte> whole(world->start.begin(), world->start.begin() + kHeader);
    whole.insert(whole.end(), buffer.begin(), buffer.end());
    const std::uint64_t payload = buffer.size();
    std::uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a, as the format says
    for (const std::byte b : buffer) h = (h ^ static_cast<std::uint64_t>(b)) * 0x100000001b3ULL;
    std::memcpy(whole.data() + 24, &payload, 8);
    std::memcpy(whole.data() + 32, &h, 8);
    buffer = std::move(whole);
  }
  try {
    e.restoreState(buffer);
  } catch (const Error&) {
    return;
  }
  try {
    e.step(20);
  } catch (const Error& error) {
    expected(error);
  }
}

void commandLineInput(std::span<const std::uint8_t> data) {
  std::vector<std::string> args{"ssx"};
  const std::string_view all = text(data);
  for (std::size_t begin = 0; begin <= all.size() && args.size() <= 64;) {
    const std::size_t end = std::min(all.find('\0', begin), all.size());
    args.emplace_back(all.substr(begin, end - begin));
    begin = end + 1;
  }
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const cli::CommandLine c = cli::parseCommandLine(static_cast<int>(argv.size()), argv.data(), out, err);
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::logic_error(std::string("the command line accepted ") + what);
  };
  if (c.exit_status) {
    require(*c.exit_status == 0 || *c.exit_status == cli::kExitBadInput, "an exit status other than 0 and 2");
    require(*c.exit_status == 0 || !err.str().empty(), "nothing said about refused arguments");
    return;
  }
  const cli::RunArgs& r = c.run;
  require(!r.duration_given || (r.duration > 0 && r.duration <= kMaxDurationSeconds), "a duration out of range");
  require(r.steps >= -1, "a negative step count");
  require(r.threads >= -1 && r.threads <= 1024, "a thread count out of range");
  require(!c.realtime_given || (r.realtime >= kMinRealtimeFactor && r.realtime <= kMaxRealtimeFactor),
          "a real-time factor out of range");
  require(r.rt_priority == 0 || (r.rt_priority >= kMinRealtimePriority && r.rt_priority <= kMaxRealtimePriority),
          "a priority out of range");
  for (double mb : {r.max_input_mb, c.validate.max_input_mb, c.sweep.max_input_mb})
    require(mb >= 1.0 / 1024 && mb <= cli::kMostMaxInputMb, "an input limit out of range");
  require(c.sweep.jobs == 0 || (c.sweep.jobs >= 1 && c.sweep.jobs <= 4096), "a job count out of range");
}

void recordingInput(std::span<const std::uint8_t> data) {
  std::vector<std::byte> bytes(data.size());
  if (!data.empty()) std::memcpy(bytes.data(), data.data(), data.size());
  try {
    const detail::McapFile f = detail::parseMcap(bytes, "fuzz.mcap");
    const int poses = f.channelId("/ssx/poses");
    std::vector<float> p, q;
    for (const auto& m : f.messages) {
      if (m.channel != poses) continue;
      try {
        detail::decodePoses(f.data(m), &p, &q);
      } catch (const Error&) {
      }
    }
  } catch (const Error&) {
  }
  // the recording as every reader takes it (times in order, pose lengths checked): once read,
  // reading any of its samples or messages never fails, and a state fails only with Error (a
  // compressed one whose frame does not decompress), never asking for more than 1,024 times its size
  try {
    const Recording r(std::move(bytes), "fuzz.mcap");
    for (std::size_t k = 0; k < r.times().size(); ++k) {
      (void)r.positions(k);
      (void)r.orientations(k);
      if (k > 0 && r.times()[k] <= r.times()[k - 1]) std::abort();
    }
    for (const auto& [topic, count] : r.channels()) (void)r.messages(topic);
    for (const Nanoseconds t : r.stateTimes()) (void)r.stateAtOrBefore(t);
  } catch (const Error&) {
  }
}

}  // namespace ssx::fuzz
