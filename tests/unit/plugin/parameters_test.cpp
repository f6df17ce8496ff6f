// Declared plugin parameters: the checks, the defaults, the docs made from them, periods that fit.
#include <ssx/ssx.hpp>

#include "test_util.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

using namespace ssx;

namespace {

namespace fs = std::filesystem;

constexpr ssx_plugin_param kDeclared[] = {
    param::real("gain", "2.5", "1/s", param::positive() & param::atMost(10), "a gain"),
    param::integer("count", "3", param::nonNegative(), "how many"),
    param::choice("mode", "fast", "fast slow", "how"),
    param::required(param::text("file", "", "where")),
    param::rate("loop_hz", "100", param::positive(), "a loop inside the plugin"),
    param::vec3("offset", "0 0 1", "m", param::any(), "an offset"),
};

std::vector<std::string> errorsOf(const std::vector<Diagnostic>& diagnostics) {
  std::vector<std::string> out;
  for (const auto& d : diagnostics)
    if (d.severity == Diagnostic::Severity::Error) out.push_back(d.str());
  return out;
}

Descriptor element(std::initializer_list<std::pair<const char*, const char*>> attributes) {
  Descriptor d("driver", {"scene.xml", 7});
  int line = 8;
  for (const auto& [k, v] : attributes) d.set(k, v, {"scene.xml", line++});
  return d;
}

// every table between <!-- parameters:NAME --> and <!-- end parameters:NAME --> in the docs
std::map<std::string, std::string> docTables() {
  std::ifstream in(fs::path(SSX_EXAMPLES_DIR) / ".." / "docs" / "scene-format.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  std::map<std::string, std::string> out;
  // (found by plain search: std::regex over a whole document recurses per character and overflows
  // the stack under AddressSanitizer)
  const std::string open = "<!-- parameters:", close = " -->\n";
  for (std::size_t at = s.find(open); at != std::string::npos; at = s.find(open, at + 1)) {
    const std::size_t name_end = s.find(close, at);
    if (name_end == std::string::npos) break;
    const std::string name = s.substr(at + open.size(), name_end - at - open.size());
    const std::size_t body = name_end + close.size();
    const std::size_t end = s.find("<!-- end parameters:" + name + " -->", body);
    if (end == std::string::npos) break;
    out[name] = s.substr(body, end - body);
  }
  return out;
}

}  // namespace

TEST_CASE("declared defaults are added and every declared check holds", "[parameters]") {
  const PluginContext context{nullptr, nullptr, 1, 1'000'000, {}};
  Descriptor d = element({{"file", "out.csv"}});
  CHECK(errorsOf(checkParameters(kDeclared, d, context, "driver 'x'")).empty());
  CHECK(d.get<double>("gain") == 2.5);
  CHECK(d.get<std::int64_t>("count") == 3);
  CHECK(d.get<std::string>("mode") == "fast");
  CHECK(d.get<Vec3>("offset") == Vec3(0, 0, 1));
  // defaults count as read: nothing is left for the unknown-parameter warnings
  CHECK(d.unusedAttributeWarnings().empty());
}

TEST_CASE("each kind of bad parameter is an error at its own line", "[parameters]") {
  const PluginContext context{nullptr, nullptr, 1, 1'000'000, {}};
  struct Case {
    const char* key;
    const char* value;
    const char* message;
  };
  const Case cases[] = {
      {"gain", "0", "parameter 'gain' must be > 0 and <= 10 1/s, got '0'"},
      {"gain", "11", "parameter 'gain' must be > 0 and <= 10 1/s, got '11'"},
      {"gain", "fast", "parameter 'gain' must be real, got 'fast'"},
      {"count", "-1", "parameter 'count' must be >= 0, got '-1'"},
      {"count", "1.5", "parameter 'count' must be int, got '1.5'"},
      {"mode", "medium", "parameter 'mode' must be one of fast, slow, got 'medium'"},
      {"offset", "1 2", "parameter 'offset' must be vec3 (\"x y z\"), got '1 2'"},
      {"loop_hz", "300", "parameter 'loop_hz' = 300 Hz: its period (3.333333333 ms) must be a whole multiple"},
  };
  for (const auto& c : cases) {
    INFO(c.key << "=" << c.value);
    Descriptor d = element({{"file", "f"}, {c.key, c.value}});
    const auto errors = errorsOf(checkParameters(kDeclared, d, context, "driver 'x'"));
    REQUIRE(errors.size() == 1);
    CHECK_THAT(errors[0], Catch::StartsWith("scene.xml:9: error: <driver>: driver 'x': "));
    CHECK_THAT(errors[0], Catch::Contains(c.message));
  }
  // a required parameter missing is an error at the element
  Descriptor none = element({});
  const auto errors = errorsOf(checkParameters(kDeclared, none, context, "driver 'x'"));
  REQUIRE(errors.size() == 1);
  CHECK_THAT(errors[0], Catch::StartsWith("scene.xml:7: error: <driver>: driver 'x': missing parameter 'file'"));
  // an undeclared one is a warning
  Descriptor extra = element({{"file", "f"}, {"gian", "1"}});
  const auto all = checkParameters(kDeclared, extra, context, "driver 'x'");
  REQUIRE(all.size() == 1);
  CHECK(all[0].str() == "scene.xml:9: warning: unknown parameter 'gian' of driver 'x' (ignored; did you mean 'gain'?)");
  // with no name near it, every name the plugin has
  Descriptor far = element({{"file", "f"}, {"zzzzzz", "1"}});
  const auto listed = checkParameters(kDeclared, far, context, "driver 'x'");
  REQUIRE(listed.size() == 1);
  CHECK(listed[0].str() == "scene.xml:9: warning: unknown parameter 'zzzzzz' of driver 'x' (ignored; it has: gain, count, "
                           "mode, file, loop_hz, offset)");
}

TEST_CASE("a loop rate fits when its period is a whole multiple of the plugin's", "[parameters]") {
  // 100 Hz is every 10 ms: plugins every 1, 2, 5 or 10 steps of 1 ms fit; 3 or 20 do not
  for (std::int64_t period : {1, 2, 5, 10, 3, 20}) {
    INFO("period " << period);
    const PluginContext context{nullptr, nullptr, period, 1'000'000, {}};
    Descriptor d = element({{"file", "f"}});
    const bool fits = 10 % period == 0;
    CHECK(errorsOf(checkParameters(kDeclared, d, context, "driver 'x'")).empty() == fits);
    if (fits) CHECK(runsPerPeriod(100.0, context) == 10 / period);
  }
}

TEST_CASE("the built-in plugin tables in the docs are their declarations", "[parameters][docs]") {
  const auto tables = docTables();
  ClassLoader loader;
  loader.addSearchDirectory(ClassLoader::installedPluginDirectory());
  int compared = 0;
  for (const auto& lib : loader.scan()) {
    REQUIRE(lib.ok);
    for (const auto& c : lib.classes) {
      if (c.name == "clock") continue;  // declares none
      INFO(c.name << ": run scripts/update_plugin_docs.py");
      REQUIRE(tables.contains(c.name));
      CHECK(tables.at(c.name) == c.parameter_table);
      ++compared;
    }
  }
  CHECK(compared >= 7);
}

TEST_CASE("a quadrotor flies with the driver's or the IMU's period above one step", "[parameters][quadrotor]") {
  // timestep 1 ms: driver every 2 steps (loops every 1 and 10 of its runs), IMU every 2 or 3 steps
  for (const char* overrides : {"<driver period=\"2\"/>", "<sensor index=\"0\" period=\"2\" noise=\"false\"/>",
                                "<sensor index=\"0\" period=\"3\" noise=\"false\"/>"}) {
    INFO(overrides);
    const std::string xml =
        "<scene><environment timestep=\"0.001\" seed=\"1\"/><type name=\"q\" file=\"mk_quad.xml\"/><ground/>"
        "<artifact name=\"quad\" type=\"q\" xyz=\"0 0 1\">" +
        std::string(overrides) + "</artifact></scene>";
    Scene s = loadSceneFromString(xml, "quad.xml", fs::path(SSX_EXAMPLES_DIR) / "artifacts");
    s.environment->step(5000);
    const Artifact& quad = *s.environment->findArtifact("quad");
    CHECK((quad.pose().position - Vec3(0, 0, 1)).norm() < 0.03);
    CHECK((quad.pose().orientation * Vec3::UnitZ()).z() > 0.99);  // upright
  }
}

TEST_CASE("plugins a program attaches itself get their declared defaults and checks at start", "[parameters]") {
  auto build = [](const char* gain) {
    auto env = std::make_unique<Environment>();
    env->classLoader().addSearchDirectory(ClassLoader::installedPluginDirectory());
    Artifact& a = env->addArtifact("body", test::at(0, 0, 1));
    a.addPhysicRoot(test::boxBody(Vec3(0.1, 0.1, 0.1), 1.0));
    Descriptor params("driver");
    if (gain != nullptr) params.set("kp", gain);
    a.setDriver(env->classLoader().createDriver("hover", "hover"), params, 1, "hover");
    return env;
  };
  auto good = build(nullptr);
  good->step(2000);  // every default in place: it holds its start
  CHECK((good->findArtifact("body")->pose().position - Vec3(0, 0, 1)).norm() < 1e-3);
  auto bad = build("-4");
  CHECK_THROWS_WITH(bad->start(), Catch::Contains("parameter 'kp' must be > 0") && Catch::EndsWith("nothing was run"));
  CHECK(bad->state() == Environment::State::Setup);
}

TEST_CASE("one plugin instance belongs to one artifact", "[parameters]") {
  Environment env;
  Artifact& a = env.addArtifact("a");
  Artifact& b = env.addArtifact("b");
  test::LambdaDriver driver([](Driver&, const StepInfo&) {});
  a.setDriver(driver, {}, 1, "lambda");
  CHECK_THROWS_WITH(b.setDriver(driver, {}, 1, "lambda"),
                    Catch::Contains("belongs to artifact 'a' already; create one instance per artifact"));
}

TEST_CASE("PluginContext::shared makes a value once per type and key, a failing make leaves nothing", "[parameters]") {
  PluginContext::SharedValues table;
  PluginContext context;
  context.shared_values = &table;
  int made = 0;
  auto make = [&] { return ++made; };
  const auto a = context.shared<int>("k", make);
  const auto b = context.shared<int>("k", make);
  CHECK(a.get() == b.get());
  CHECK(made == 1);
  CHECK(*context.shared<int>("other", make) == 2);
  CHECK(*context.shared<double>("k", [] { return 0.5; }) == 0.5);  // another type under the same key
  CHECK_THROWS_WITH(context.shared<long>("x", []() -> long { throw std::runtime_error("no"); }), "no");
  CHECK(*context.shared<long>("x", [] { return 7L; }) == 7);
  // without a table every call makes its own
  const PluginContext alone;
  CHECK(alone.shared<int>("k", make).get() != alone.shared<int>("k", make).get());
  CHECK(made == 4);
}
