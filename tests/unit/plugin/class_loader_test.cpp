#include <ssx/ssx.hpp>

#include <ssx/plugin_abi.hpp>

#include <catch2/catch.hpp>

#include <bit>
#include <dlfcn.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

using namespace ssx;
using Catch::Contains;

namespace {

const std::string kDir = SSX_TEST_PLUGIN_DIR;

std::string loadError(ClassLoader& loader, const std::string& plugin) {
  try {
    loader.load(plugin);
  } catch (const PluginError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("a good plugin library loads and creates classes of each kind", "[plugins]") {
  ClassLoader loader;
  loader.addSearchDirectory(kDir);
  const auto path = loader.load("test_good");
  CHECK(path.filename() == "libssx_test_good.so");
  Driver& d = loader.createDriver("test_good", "spinner");
  Sensor& s = loader.createSensor("test_good", "counter");
  SimulationExtension& e = loader.createExtension("test_good", "marker");
  CHECK(dynamic_cast<const ClockMeasurement*>(&s.latest()) != nullptr);  // type info shared across libraries
  (void)d;
  (void)e;
  // two classes of the same library, one load
  CHECK(loader.load("test_good") == path);
}

TEST_CASE("a class's instances are built side by side, each on its own cache lines, and each destroyed",
          "[plugins]") {
  ClassLoader loader;
  loader.addSearchDirectory(kDir);
  const ssx_plugin_class& type = loader.classInfo("test_good", "tally", PluginKind::Driver);
  REQUIRE(type.construct != nullptr);
  const auto path = loader.load("test_good");
  void* library = dlopen(path.c_str(), RTLD_NOW | RTLD_NOLOAD);
  REQUIRE(library != nullptr);
  const auto live = reinterpret_cast<int (*)()>(dlsym(library, "ssx_test_live_tallies"));
  REQUIRE(live != nullptr);
  std::vector<std::uintptr_t> at;
  for (int i = 0; i < 40; ++i) {  // more than the first chunk holds
    at.push_back(reinterpret_cast<std::uintptr_t>(&loader.createDriver("test_good", "tally")));
    (void)loader.createDriver("test_good", "spinner");  // another class in between: its own pool
  }
  CHECK(live() == 40);
  // the chunks hold 1, 2, 4, 8, ... instances: instance i is in chunk floor(log2(i + 1))
  auto chunk = [](std::size_t i) { return std::bit_width(i + 1) - 1; };
  const std::uintptr_t slot = at[2] - at[1];
  CHECK(slot >= type.instance_size);
  CHECK(slot % 64 == 0);
  for (std::size_t i = 0; i < at.size(); ++i) {
    INFO("instance " << i);
    CHECK(at[i] % 64 == 0);
    if (i > 0 && chunk(i) == chunk(i - 1)) CHECK(at[i] - at[i - 1] == slot);  // side by side in a chunk
  }
  // each instance is known as its class's, and nothing else is: not an address inside one, not
  // a slot no instance holds yet, not an object made elsewhere
  const ssx_plugin_class& spinner = loader.classInfo("test_good", "spinner", PluginKind::Driver);
  for (const std::uintptr_t a : at) {
    CHECK(loader.classOf(reinterpret_cast<const void*>(a)) == &type);
    CHECK(loader.classOf(reinterpret_cast<const void*>(a + 8)) == nullptr);
  }
  CHECK(loader.classOf(reinterpret_cast<const void*>(at.back() + slot)) == nullptr);
  const Driver& last_spinner = loader.createDriver("test_good", "spinner");
  CHECK(loader.classOf(&last_spinner) == &spinner);
  const int elsewhere = 0;
  CHECK(loader.classOf(&elsewhere) == nullptr);
  loader.destroyInstances();
  CHECK(live() == 0);
  CHECK(loader.classOf(reinterpret_cast<const void*>(at[0])) == nullptr);
  dlclose(library);
}

TEST_CASE("plugin instances drive an environment built in code", "[plugins]") {
  Environment env;
  env.classLoader().addSearchDirectory(kDir);
  PhysicNodeSpec body;
  body.name = "body";
  body.mass = 1.0;
  body.shapes.push_back(Shape::box(Vec3(0.1, 0.1, 0.1)));
  Artifact& a = env.addArtifact("top", {Vec3(0, 0, 10), Quat::Identity()});
  a.addPhysicRoot(body);
  Descriptor params("driver");
  params.set("torque", 0.5);
  a.setDriver(env.classLoader().createDriver("test_good", "spinner"), params, 1, "spinner");
  env.step(11);
  // 10 steps of 0.5 N m on Izz = 1/600 kg m^2 (the first step's torque acts from step 1 on)
  CHECK(a.state().angular_velocity.z() == Approx(10 * 0.001 * 0.5 * 600).epsilon(1e-9));
}

TEST_CASE("plugin load failures name the plugin, every path tried and the reason", "[plugins]") {
  ClassLoader loader;
  loader.addSearchDirectory("/nonexistent/plugins");
  loader.addSearchDirectory(kDir);

  SECTION("not found anywhere") {
    const std::string e = loadError(loader, "teleporter");
    CHECK_THAT(e, Contains("plugin 'teleporter' could not be loaded; tried:"));
    CHECK_THAT(e, Contains("/nonexistent/plugins/libssx_teleporter.so: not found"));
    CHECK_THAT(e, Contains(kDir + "/libssx_teleporter.so: not found"));
    CHECK_THAT(e, Contains(kDir + "/libteleporter.so: not found"));
    CHECK_THAT(e, Contains(kDir + "/teleporter.so: not found"));
  }
  SECTION("wrong ABI version") {
    CHECK_THAT(loadError(loader, "test_wrong_abi"),
               Contains("libssx_test_wrong_abi.so: plugin ABI version 999, this ssx loads version " + std::to_string(SSX_PLUGIN_ABI_VERSION)));
  }
  SECTION("build tag mismatch") {
    CHECK_THAT(loadError(loader, "test_wrong_tag"), Contains("built for 'ssx 0.0; libc++', this ssx is 'ssx 0.1;"));
  }
  SECTION("no manifest symbol") {
    CHECK_THAT(loadError(loader, "test_no_manifest"),
               Contains("not an ssx plugin: it has no 'ssx_plugin_manifest_v1' symbol"));
  }
  SECTION("undefined symbol, demangled") {
    const std::string e = loadError(loader, "test_undefined_symbol");
    CHECK_THAT(e, Contains("undefined symbol: _ZN7missing12solveRiccatiEi"));
    CHECK_THAT(e, Contains("(missing::solveRiccati(int))"));
  }
  SECTION("not a library") {
    CHECK_THAT(loadError(loader, "test_garbage"), Contains("libssx_test_garbage.so: not a shared library (no ELF header"));
  }
  SECTION("a truncated copy: a message, not SIGBUS inside dlopen") {
    const std::filesystem::path dir = std::filesystem::current_path() / "truncated_plugin";
    std::filesystem::create_directories(dir);
    std::ifstream in(kDir + "/libssx_test_good.so", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(dir / "libssx_test_cut.so", std::ios::binary) << bytes.substr(0, bytes.size() * 3 / 4);
    ClassLoader cut;
    cut.addSearchDirectory(dir);
    CHECK_THAT(loadError(cut, "test_cut"), Contains("libssx_test_cut.so: truncated: its section table ends at byte"));
    const auto listed = cut.scan();
    REQUIRE(listed.size() == 1);
    CHECK_FALSE(listed[0].ok);
    CHECK_THAT(listed[0].problem, Contains("truncated"));
  }
}

TEST_CASE("class lookup failures say what the library has", "[plugins]") {
  ClassLoader loader;
  loader.addSearchDirectory(kDir);
  CHECK_THROWS_WITH(loader.createDriver("test_good", "rocket"),
                    Contains("has no class 'rocket'; it has: spinner (driver), counter (sensor), marker (extension), bomb (driver), tally (driver)"));
  CHECK_THROWS_WITH(loader.createDriver("test_good", "counter"), Contains("class 'counter' is a sensor, not a driver"));
  CHECK_THROWS_WITH(loader.createExtension("test_good", "spinner"),
                    Contains("class 'spinner' is a driver, not an extension"));
}

TEST_CASE("a throwing or null-returning constructor is reported", "[plugins]") {
  ClassLoader loader;
  loader.addSearchDirectory(kDir);
  CHECK_THROWS_WITH(loader.createDriver("test_throwing", "fragile"),
                    Contains("creating 'fragile' failed: calibration file not found"));
  CHECK_THROWS_WITH(loader.createSensor("test_null_create", "ghost"),
                    Contains("creating 'ghost' failed: the constructor returned null"));
}

TEST_CASE("scanning lists every library with its classes and check result", "[plugins]") {
  ClassLoader loader;
  loader.addSearchDirectory(kDir);
  const auto libs = loader.scan();
  int ok = 0, bad = 0;
  bool saw_good = false;
  for (const auto& lib : libs) {
    (lib.ok ? ok : bad) += 1;
    if (lib.path.filename() == "libssx_test_good.so") {
      saw_good = true;
      REQUIRE(lib.classes.size() == 5);
      CHECK(lib.classes[1].kind == PluginKind::Sensor);
      CHECK(lib.classes[1].name == "counter");
    }
  }
  CHECK(saw_good);
  CHECK(ok == 3);   // good, throwing, null_create pass the manifest checks
  CHECK(bad == 5);  // wrong_abi, wrong_tag, no_manifest, undefined_symbol, garbage
}

TEST_CASE("the installed plugin directory is found beside libssx", "[plugins]") {
  const auto dir = ClassLoader::installedPluginDirectory();
  CHECK(dir.filename() == "plugins");
  CHECK(std::filesystem::exists(dir / "libssx_hover.so"));
}
