// The diff_drive plugin library (plugins/diff_drive/plugin.cpp): what its manifest offers, as the
// loader and `ssx plugins` read it.
#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <set>
#include <string>

using namespace ssx;

TEST_CASE("the diff_drive library offers one driver, diff_drive, its parameters in a table per part", "[diff_drive]") {
  const PluginLibraryInfo info = ClassLoader::inspect(ClassLoader::installedPluginDirectory() / "libssx_diff_drive.so");
  INFO(info.problem);
  REQUIRE(info.ok);
  REQUIRE(info.classes.size() == 1);
  const auto& c = info.classes[0];
  CHECK(c.name == "diff_drive");
  CHECK(c.kind == PluginKind::Driver);
  std::size_t at = 0;
  for (const char* part : {"**drive**", "**controller**", "**hold**"}) {
    INFO(part);
    const auto found = c.parameter_table.find(part, at);
    REQUIRE(found != std::string::npos);
    at = found;
  }
  ClassLoader loader;
  loader.addSearchDirectory(ClassLoader::installedPluginDirectory());
  const ssx_plugin_class& cls = loader.classInfo("diff_drive", "diff_drive", PluginKind::Driver);
  std::set<std::string> names;
  for (std::size_t i = 0; i < cls.param_count; ++i) CHECK(names.insert(cls.params[i].name).second);
  CHECK(names.count("model") + names.count("controller") + names.count("hold") == 3);
}
