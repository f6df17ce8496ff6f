// The camera sensor plugin.
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

TEST_CASE("render: a camera sensor without a drawing engine fails at start and says what to do", "[render]") {
  Scene s = loadRenderScene(R"(<type name="post" file="camera_post.xml"/><artifact name="eye" type="post"/>)");
  CHECK_THROWS_WITH(s.environment->start(), Catch::Contains("engine=\"osmesa\""));
}
