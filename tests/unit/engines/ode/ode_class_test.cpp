// ODE's entry in the engine registry: its declared settings are OdeSettings' defaults, a scene's
// values reach the typed settings, and a model prints them back.
#include <ssx/physic_engine.hpp>
#include <ssx/scene.hpp>

#include "engine_util.hpp"
#include "scene_util.hpp"

#include <catch2/catch.hpp>

using namespace ssx;
using Catch::Contains;

TEST_CASE("ode's settings: declared defaults are OdeSettings', a scene's values reach the engine", "[engines][ode]") {
  const PhysicEngineClass* ode = findPhysicEngine("ode");
  REQUIRE(ode != nullptr);
  REQUIRE(ode->configure);
  REQUIRE(ode->describe);
  // the declared defaults, configured, are the typed defaults, and describe gives them back
  PhysicsSettings from_defaults;
  from_defaults.ode.iterations = 1;  // (configure must set every field)
  from_defaults.ode.partitions = 1;
  CHECK(test::typedDefaultsMismatch(*ode, from_defaults) == std::vector<std::string>{});
  // a scene's values
  const SceneModel model = parseSceneString(
      R"(<scene><physics solver="exact" iterations="35" contact_surface_layer="0.002" partitions="4"/></scene>)", "m.xml",
      ".", {});
  const OdeSettings& o = model.settings.physics.ode;
  CHECK(o.solver == OdeSettings::Solver::Exact);
  CHECK(o.iterations == 35);
  CHECK(o.contact_surface_layer == 0.002);
  CHECK(o.partitions == 4);
  CHECK(o.sor == OdeSettings{}.sor);
  CHECK_THAT(model.toXml(), Contains(R"(solver="exact" iterations="35" sor="1.3")") && Contains(R"(partitions="4")"));
  // refused as a plugin's parameters are, with the attribute's line
  CHECK_THROWS_WITH(parseSceneString("<scene>\n<physics\n max_contacts=\"0\"/></scene>", "m.xml", ".", {}),
                    Contains("m.xml:3: error: <physics>: ode engine: parameter 'max_contacts' must be"));
}
