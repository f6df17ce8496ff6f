// Bullet's entry in the engine registry: its declared settings are BulletSettings' defaults, a
// scene's values reach the typed settings, and a model prints them back.
#include <ssx/physic_engine.hpp>
#include <ssx/scene.hpp>

#include "engine_util.hpp"
#include "scene_util.hpp"

#include <catch2/catch.hpp>

using namespace ssx;
using Catch::Contains;

TEST_CASE("bullet's settings: declared defaults are BulletSettings', a scene's values reach the engine",
          "[engines][bullet]") {
  const PhysicEngineClass* bullet = findPhysicEngine("bullet");
  REQUIRE(bullet != nullptr);
  PhysicsSettings from_defaults;
  from_defaults.bullet.iterations = 1;
  from_defaults.bullet.split_impulse = false;
  CHECK(test::typedDefaultsMismatch(*bullet, from_defaults) == std::vector<std::string>{});
  const SceneModel model = parseSceneString(
      R"(<scene><physics engine="bullet" iterations="25" split_impulse="false" linear_slop="0.001"/></scene>)", "m.xml",
      ".", {});
  const BulletSettings& b = model.settings.physics.bullet;
  CHECK(b.iterations == 25);
  CHECK_FALSE(b.split_impulse);
  CHECK(b.linear_slop == 0.001);
  CHECK(b.erp == BulletSettings{}.erp);
  CHECK_THAT(model.toXml(), Contains(R"(engine="bullet")") && Contains(R"(iterations="25")") &&
                                Contains(R"(split_impulse="false")"));
  CHECK_THROWS_WITH(parseSceneString(R"(<scene><physics engine="bullet" erp="1.5"/></scene>)", "m.xml", ".", {}),
                    Contains("m.xml:1: error: <physics>: bullet engine: parameter 'erp' must be"));
}
