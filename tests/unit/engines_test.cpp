// Engine factories: the engines a build offers, by name; an unknown name lists the ones there are;
// the null renderer draws nothing and says how to get images.
#include <ssx/physic_engine.hpp>
#include <ssx/render.hpp>

#include <catch2/catch.hpp>

#include <algorithm>

using namespace ssx;
using Catch::Contains;

TEST_CASE("engines: every physics engine offered by name is made under that name", "[engines]") {
  const auto names = physicEngineNames();
  CHECK(names == std::vector<std::string>{"ode", "bullet"});
  for (const auto& name : names) {
    PhysicsSettings settings;
    settings.engine = name;
    const auto engine = createPhysicEngine(settings);
    REQUIRE(engine != nullptr);
    CHECK(engine->name() == name);
  }
  PhysicsSettings wrong;
  wrong.engine = "physx";
  CHECK_THROWS_WITH(createPhysicEngine(wrong), Contains("unknown physics engine 'physx' (available: ode, bullet)"));
}

TEST_CASE("engines: the null renderer draws no pixels; unknown renderers list those there are", "[engines][render]") {
  const auto names = renderEngineNames();
  REQUIRE(std::find(names.begin(), names.end(), "null") != names.end());
  RenderSettings settings;
  const auto null = createRenderEngine(settings);
  CHECK(null->name() == "null");
  CHECK_FALSE(null->drawsPixels());
  Image image;
  CHECK_THROWS_WITH(null->renderView(CameraView{}, {}, Color{}, image), Contains("engine=\"osmesa\""));
  settings.engine = "vulkan";
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  CHECK_THROWS_WITH(createRenderEngine(settings), Contains("unknown render engine 'vulkan' (available: " + list + ")"));
}
