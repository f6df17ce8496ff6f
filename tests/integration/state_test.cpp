// Saving and restoring a world: continuing after a restore is the run that was never interrupted.
#include <ssx/ssx.hpp>

#include "state_scene.hpp"
#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

using namespace ssx;
using ssx::test::loadStateScene;
using ssx::test::stateSceneXml;
namespace fs = std::filesystem;

namespace {

std::vector<std::uint64_t> hashes(Environment& env, int steps, std::size_t* contacts = nullptr) {
  std::vector<std::uint64_t> out;
  for (int i = 0; i < steps; ++i) {
    env.step();
    out.push_back(env.stateHash());
    if (contacts != nullptr) *contacts += env.physics().contactCount();
  }
  return out;
}

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

int runCli(const std::string& args) {
  std::string command = SSX_CLI_PATH;
  command += ' ';
  command += args;
  command += " 2>/dev/null";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("a restored world continues bitwise as the uninterrupted run, on 1, 2 and 4 threads, on either engine",
          "[state]") {
  const std::string engine = GENERATE("ode", "bullet");
  INFO(engine);
  Scene original = loadStateScene(1, "", engine);
  Environment& env = *original.environment;
  env.step(300);
  const std::vector<std::byte> saved = env.saveState();
  std::size_t contacts = 0;
  const std::vector<std::uint64_t> reference = hashes(env, 300, &contacts);
  CHECK(contacts > 0);  // bodies touched after the save

  for (int threads : {1, 2, 4}) {
    INFO(threads << " thread(s), a freshly loaded scene");
    Scene fresh = loadStateScene(threads, "", engine);
    fresh.environment->restoreState(saved);
    CHECK(fresh.environment->stepCount() == 300);
    CHECK(hashes(*fresh.environment, 300) == reference);
  }
  // the same environment, rewound: an exact replay
  env.restoreState(saved);
  CHECK(hashes(env, 300) == reference);
  // and saving again right after a restore gives the same bytes
  env.restoreState(saved);
  CHECK(env.saveState() == saved);
}

TEST_CASE("ssx run --save-state and --load-state continue a run in another process", "[state][cli]") {
  const fs::path dir = fs::current_path() / "state_cli";
  fs::create_directories(dir);
  const fs::path scene = dir / "scene.xml";
  std::ofstream(scene) << stateSceneXml(2, (dir / "poses.csv").string());
  const std::string sceneArg = "run " + scene.string() + " --fast --quiet ";

  REQUIRE(runCli(sceneArg + "--steps 400 --save-state " + (dir / "whole.bin").string()) == 0);
  REQUIRE(runCli(sceneArg + "--steps 150 --threads 1 --save-state " + (dir / "first.bin").string()) == 0);
  REQUIRE(runCli(sceneArg + "--steps 250 --threads 4 --load-state " + (dir / "first.bin").string() +
                 " --save-state " + (dir / "rest.bin").string()) == 0);
  CHECK(slurp(dir / "whole.bin") == slurp(dir / "rest.bin"));
  CHECK_FALSE(fs::exists(dir / "rest.bin.partial"));

  // a state that does not fit is refused before anything starts: the logger's file stays as it was
  std::ofstream(dir / "poses.csv") << "kept\n";
  std::string bad = slurp(dir / "first.bin");
  bad.resize(bad.size() / 2);
  std::ofstream(dir / "bad.bin", std::ios::binary) << bad;
  CHECK(runCli(sceneArg + "--steps 10 --load-state " + (dir / "bad.bin").string()) == 2);
  CHECK(slurp(dir / "poses.csv") == "kept\n");
}
