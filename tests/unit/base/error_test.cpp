// Errors: where a problem was is said the same way everywhere ("file:line", "file" or "<code>"),
// and a step error carries the artifact, the plugin and the step it happened in.
#include <ssx/error.hpp>

#include <catch2/catch.hpp>

#include <string>
#include <vector>

using namespace ssx;

TEST_CASE("a source location reads file:line, file, or <code>", "[error]") {
  CHECK(SourceLocation{"scene.xml", 12}.str() == "scene.xml:12");
  CHECK(SourceLocation{"scene.xml", 0}.str() == "scene.xml");
  CHECK(SourceLocation{"", 7}.str() == "<code>");
  CHECK(SourceLocation{}.str() == "<code>");
}

TEST_CASE("a configuration error's message is file:line: error: detail", "[error]") {
  const ConfigError e({"a/b.xml", 3}, "attribute 'mass' must be positive");
  CHECK(std::string(e.what()) == "a/b.xml:3: error: attribute 'mass' must be positive");
  CHECK(e.detail() == "attribute 'mass' must be positive");
  CHECK(e.where().line == 3);
  CHECK(std::string(ConfigError({}, "no file").what()) == "<code>: error: no file");
  // every ssx error is caught as ssx::Error and as std::runtime_error
  CHECK_THROWS_AS(throw ConfigError({}, "x"), Error);
  CHECK_THROWS_AS(throw ConfigError({}, "x"), std::runtime_error);
}

TEST_CASE("a step error names the step, the artifact and the plugin", "[error]") {
  const StepError e("q7", "driver quadrotor", 42, "rotor 2 command is NaN");
  CHECK(std::string(e.what()) == "step 42: artifact 'q7', driver quadrotor: rotor 2 command is NaN");
  CHECK(e.artifact() == "q7");
  CHECK(e.plugin() == "driver quadrotor");
  CHECK(e.step() == 42);
}

TEST_CASE("did you mean: the nearest name within a typing slip, case aside", "[error]") {
  const std::vector<std::string> names{"timestep", "threads", "seed", "csv_logger", "quadrotor"};
  CHECK(didYouMean("timestpe", names) == " (did you mean 'timestep'?)");  // two letters swapped: one edit
  CHECK(didYouMean("thraeds", names) == " (did you mean 'threads'?)");
  CHECK(didYouMean("csv_loger", names) == " (did you mean 'csv_logger'?)");
  CHECK(didYouMean("QuadRotor", names) == " (did you mean 'quadrotor'?)");
  CHECK(didYouMean("sed", names) == " (did you mean 'seed'?)");           // short names: one edit
  CHECK(didYouMean("colour", names).empty());
  CHECK(didYouMean("seed", names).empty());  // the name itself is no suggestion
  CHECK(nearestName("thread", names) == "threads");
  CHECK(nearestName("xyz", {}).empty());
}
