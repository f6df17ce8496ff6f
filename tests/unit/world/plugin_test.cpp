// Plugins as the scene loader uses them: a type's validate and what swarm members share.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <dlfcn.h>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("a plugin's validate works out what a swarm's members share once per scene load", "[scene][plugins]") {
  // the test plugin's spinner counts how often its validate makes its shared value (per torque)
  void* library = dlopen((fs::path(SSX_TEST_PLUGIN_DIR) / "libssx_test_good.so").c_str(), RTLD_NOW);
  REQUIRE(library != nullptr);
  const auto made = reinterpret_cast<int (*)()>(dlsym(library, "ssx_test_spinner_checks"));
  REQUIRE(made != nullptr);
  const std::string xml = R"(<scene>
    <type name="spinner" file="spinner.xml"/>
    <swarm type="spinner" count="5" name="a{i}" spacing="1"><driver torque="0.2"/></swarm>
    <swarm type="spinner" count="3" name="b{i}" spacing="1" xyz="0 10 0"><driver torque="1.{i}"/></swarm>
  </scene>)";
  const int before = made();
  (void)loadSceneFromString(xml, "memory.xml", kData / "valid", testOptions());
  CHECK(made() - before == 4);  // 0.2 once for five members, then 1.0, 1.1 and 1.2
  (void)loadSceneFromString(xml, "memory.xml", kData / "valid", testOptions());
  CHECK(made() - before == 8);  // each load has its own table
  // what the shared check refuses is reported where the value was given
  CHECK_THROWS_WITH(loadSceneFromString(R"(<scene>
    <type name="spinner" file="spinner.xml"/>
    <swarm type="spinner" count="3" name="c{i}" spacing="1"><driver torque="2000"/></swarm>
  </scene>)",
                                        "memory.xml", kData / "valid", testOptions()),
                    Contains("memory.xml:3: error: <driver>: driver 'spinner': torque above 1000 N m"));
  dlclose(library);
}
