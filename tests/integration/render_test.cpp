// Rendering in a run: drawing never changes what is simulated.
// Headless (OSMesa); every test name contains "render".
#include <ssx/ssx.hpp>

#include "render_util.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

using namespace ssx;
using namespace ssx::test;
namespace fs = std::filesystem;

TEST_CASE("render: drawing frames and camera images does not change the simulation", "[render][determinism]") {
  REQUIRE(haveOsmesa());  // dev.sh installs libosmesa6-dev
  auto run = [](const std::string& engine, bool cameras) {
    const fs::path frames = fs::current_path() / "frames";
    fs::remove_all(frames);
    std::string xml = "<render engine=\"" + engine + "\" rate_hz=\"25\">";
    if (cameras) xml += "<camera name=\"top\" xyz=\"0 -8 6\" frames=\"" + frames.string() + "\"/>";
    xml += R"(</render><ground/>
      <type name="post" file="camera_post.xml"/><type name="ball" file="yellow_ball.xml"/>
      <type name="quad" file=")" + std::string(SSX_EXAMPLES_DIR) + R"(/artifacts/mk_quad.xml"/>
      <swarm type="quad" count="6" name="q{i}" spacing="1.5" xyz="0 0 0.04"/>)";
    if (cameras) xml += R"(<artifact name="eye" type="post" xyz="-3 0 1"/>)";
    xml += R"(<artifact name="ball" type="ball" xyz="2 3 2"/>)";
    Scene s = loadRenderScene(xml);
    s.environment->step(300);
    return s.environment->stateHash();
  };
  const std::uint64_t plain = run("null", false);
  CHECK(run("osmesa", true) == plain);
  CHECK(run("osmesa", false) == plain);
}
