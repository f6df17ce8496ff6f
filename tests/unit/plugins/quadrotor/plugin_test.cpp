// The quadrotor plugin library (plugins/quadrotor/plugin.cpp): what its manifest offers, as the
// loader and `ssx plugins` read it.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cstring>
#include <set>
#include <string>

using namespace ssx;

TEST_CASE("the quadrotor library offers one driver, quadrotor, its parameters in a table per part", "[quadrotor]") {
  const auto file = ClassLoader::installedPluginDirectory() / "libssx_quadrotor.so";
  const PluginLibraryInfo info = ClassLoader::inspect(file);
  INFO(info.problem);
  REQUIRE(info.ok);
  REQUIRE(info.classes.size() == 1);
  const auto& c = info.classes[0];
  CHECK(c.name == "quadrotor");
  CHECK(c.kind == PluginKind::Driver);
  CHECK(!c.doc.empty());
  // the parts, each under its name and in this order
  std::size_t at = 0;
  for (const char* part : {"**vehicle**", "**ground effect**", "**wind**", "**downwash**", "**controller (TeleKyb)**",
                           "**references**"}) {
    INFO(part);
    const auto found = c.parameter_table.find(part, at);
    REQUIRE(found != std::string::npos);
    at = found;
  }

  // every parameter declared once, with a part (a scene names them without their part)
  ClassLoader loader;
  loader.addSearchDirectory(ClassLoader::installedPluginDirectory());
  const ssx_plugin_class& cls = loader.classInfo("quadrotor", "quadrotor", PluginKind::Driver);
  std::set<std::string> names;
  for (std::size_t i = 0; i < cls.param_count; ++i) {
    INFO(cls.params[i].name);
    CHECK(names.insert(cls.params[i].name).second);
    CHECK(cls.params[i].group != nullptr);
  }
  CHECK(names.count("preset") + names.count("reference") == 2);
}
