// Presets: files of parameter values a class's parameters start from, found by name or path,
// checked with their file and line.
#include <ssx/ssx.hpp>

#include "plugin/presets.hpp"

#include <catch2/catch.hpp>

#include <stdlib.h>

#include <filesystem>
#include <fstream>

using namespace ssx;

namespace {

namespace fs = std::filesystem;

constexpr ssx_plugin_param kWidget[] = {
    param::text("preset", "base", "the values to start from"),
    param::real("gain", "1", "", param::positive(), "a gain"),
    param::choice("mode", "fast", "fast slow", "how"),
    param::integer("count", "3", param::nonNegative(), "how many"),
};

// a class that shares the widget's presets but declares only some of its parameters
constexpr ssx_plugin_param kGadget[] = {
    [] {
      ssx_plugin_param p = param::text("preset", "base", "the widget's presets");
      p.choices = "widget";
      return p;
    }(),
    param::real("gain", "1", "", param::positive(), "a gain"),
};

// a directory of this test's own (ctest runs the cases in parallel processes)
struct Dir {
  fs::path path;
  Dir() {
    std::string pattern = (fs::temp_directory_path() / "ssx_presets_XXXXXX").string();
    REQUIRE(mkdtemp(pattern.data()) != nullptr);
    path = pattern;
  }
  ~Dir() { fs::remove_all(path); }
  fs::path file(const std::string& name, const std::string& text) const {
    fs::create_directories((path / name).parent_path());
    std::ofstream(path / name) << text;
    return path / name;
  }
};

const std::string kBase =
    "<preset class=\"widget\">\n"
    "  <param name=\"gain\" value=\"4.5\"/>\n"
    "  <param name=\"mode\" value=\"slow\"/>\n"
    "</preset>\n";

std::string errorOf(const std::vector<Diagnostic>& found) {
  REQUIRE(found.size() == 1);
  CHECK(found[0].severity == Diagnostic::Severity::Error);
  return found[0].str();
}

}  // namespace

TEST_CASE("a preset gives the values an element leaves out, each where its file wrote it", "[presets]") {
  Dir d;
  const fs::path base = d.file("widget/base.xml", kBase);
  detail::Presets presets({d.path}, kDefaultMaxInputBytes);
  // by its declared default
  Descriptor params("driver", {"scene.xml", 3});
  params.set("count", "7", {"scene.xml", 3});
  fs::path used;
  CHECK(presets.apply(params, "widget", kWidget, "driver 'widget'", &used).empty());
  CHECK(used == base);
  CHECK(params.get<double>("gain") == 4.5);
  CHECK(params.get<std::string>("mode") == "slow");
  CHECK(params.get<std::int64_t>("count") == 7);
  CHECK(params.find("gain")->where.str() == base.string() + ":2");
  // the element's own value wins, by name or by path
  d.file("widget/strong.xml", "<preset class=\"widget\"><param name=\"gain\" value=\"9\"/></preset>");
  for (const std::string& name : {std::string("strong"), (d.path / "widget/strong.xml").string()}) {
    Descriptor own("driver", {"scene.xml", 5});
    own.set("preset", name, {"scene.xml", 5}).set("mode", "fast", {"scene.xml", 5});
    CHECK(presets.apply(own, "widget", kWidget, "driver 'widget'").empty());
    CHECK(own.get<double>("gain") == 9);
    CHECK(own.get<std::string>("mode") == "fast");
  }
  // a relative path is relative to the file that names it
  d.file("scenes/mine.xml", "<preset class=\"widget\"><param name=\"gain\" value=\"2\"/></preset>");
  Descriptor relative("driver", {(d.path / "scenes/scene.xml").string(), 4});
  relative.set("preset", "mine.xml", {(d.path / "scenes/scene.xml").string(), 4});
  CHECK(presets.apply(relative, "widget", kWidget, "driver 'widget'").empty());
  CHECK(relative.get<double>("gain") == 2);
}

TEST_CASE("a preset that is not there: the default stands for the class's defaults, a named one is an error",
          "[presets]") {
  Dir d;
  d.file("widget/other.xml", kBase);
  detail::Presets presets({d.path / "none", d.path}, kDefaultMaxInputBytes);
  Descriptor quiet("driver", {"scene.xml", 3});
  CHECK(presets.apply(quiet, "widget", kWidget, "driver 'widget'").empty());
  CHECK_FALSE(quiet.has("gain"));
  Descriptor named("driver", {"scene.xml", 3});
  named.set("preset", "missing", {"scene.xml", 4});
  const std::string e = errorOf(presets.apply(named, "widget", kWidget, "driver 'widget'"));
  CHECK_THAT(e, Catch::StartsWith("scene.xml:4: error: <driver>: driver 'widget': no preset 'missing' for widget"));
  CHECK_THAT(e, Catch::Contains("there are: other"));
  Descriptor path("driver", {"scene.xml", 3});
  path.set("preset", "gone/missing.xml", {"scene.xml", 6});
  CHECK_THAT(errorOf(presets.apply(path, "widget", kWidget, "driver 'widget'")),
             Catch::StartsWith("scene.xml:6: error: <driver>: driver 'widget': preset file 'gone/missing.xml' not found"));
}

TEST_CASE("a malformed preset is refused with its file and line, and sets nothing", "[presets]") {
  Dir d;
  struct Case {
    const char* text;
    int line;
    const char* message;
  };
  const Case cases[] = {
      {"<values class=\"widget\"/>", 1, "the root element of a preset file must be <preset class=\"widget\">"},
      {"<preset class=\"gadget\"/>", 1, "this preset is for 'gadget', not 'widget'"},
      {"<preset class=\"widget\" colour=\"red\"/>", 1, "<preset>: unknown attribute 'colour'"},
      {"<preset class=\"widget\">\n<value name=\"gain\" value=\"2\"/></preset>", 2, "unknown element <value> in <preset>"},
      {"<preset class=\"widget\">\n<param name=\"gain\"/></preset>", 2, "<param>: needs 'name' and 'value'"},
      {"<preset class=\"widget\">\n<param name=\"gain\" value=\"2\"/>\n<param name=\"gain\" value=\"3\"/></preset>", 3,
       "<param>: 'gain' is given twice"},
      {"<preset class=\"widget\">\n<param name=\"preset\" value=\"x\"/></preset>", 2,
       "<param>: a preset does not name another preset"},
      {"<preset class=\"widget\">\n<param name=\"mode\" value=\"slow\"/>\n<param name=\"gian\" value=\"2\"/></preset>", 3,
       "<param>: 'gian' is not a parameter of widget (did you mean 'gain'?)"},
      {"<preset class=\"widget\">\n<param name=\"gain\" value=\"2\"></preset>", 2, ""},  // not XML
  };
  int k = 0;
  for (const Case& c : cases) {
    INFO(c.text);
    const fs::path file = d.file("widget/bad" + std::to_string(++k) + ".xml", c.text);
    detail::Presets presets({d.path}, kDefaultMaxInputBytes);
    Descriptor params("driver", {"scene.xml", 3});
    params.set("preset", file.stem().string(), {"scene.xml", 3});
    const std::string e = errorOf(presets.apply(params, "widget", kWidget, "driver 'widget'"));
    CHECK_THAT(e, Catch::StartsWith(file.string() + ":" + std::to_string(c.line) + ": error: <driver>: driver 'widget': "));
    CHECK_THAT(e, Catch::Contains(c.message));
    CHECK(params.attributes().size() == 1);
  }
}

TEST_CASE("a class sharing another's presets takes the values it declares, and a class without presets is untouched",
          "[presets]") {
  Dir d;
  d.file("widget/base.xml", kBase);
  detail::Presets presets({d.path}, kDefaultMaxInputBytes);
  Descriptor gadget("driver", {"scene.xml", 3});
  CHECK(presets.apply(gadget, "gadget", kGadget, "driver 'gadget'").empty());
  CHECK(gadget.get<double>("gain") == 4.5);
  CHECK_FALSE(gadget.has("mode"));  // not one of the gadget's
  const ssx_plugin_param plain[] = {param::real("gain", "1", "", param::positive(), "a gain")};
  Descriptor other("driver", {"scene.xml", 3});
  other.set("preset", "base", {"scene.xml", 3});
  CHECK(presets.apply(other, "widget", plain, "driver 'widget'").empty());
  CHECK(other.attributes().size() == 1);
}
