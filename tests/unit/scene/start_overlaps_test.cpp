// A robot that starts inside another artifact is an error when the scene is built, at its line,
// naming both (xml/start_overlaps.cpp): resting on a surface is not, a placement may allow it,
// ghosts and static shapes among themselves are left alone, and a swarm says it once.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <string>
#include <vector>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::Contains;
using Catch::StartsWith;

namespace {

// the errors of a scene of crates (20 cm boxes) and balls (5 cm spheres), as "line: message"
std::vector<std::string> errorsOf(const std::string& body, const std::string& engine = "ode") {
  const std::string xml = "<scene>\n  <physics engine=\"" + engine +
                          "\"/>\n  <type name=\"crate\" file=\"crate.xml\"/>\n  <type name=\"ball\" file=\"ball.xml\"/>\n" +
                          body + "</scene>\n";
  try {
    (void)loadSceneFromString(xml, "start.xml", kData / "valid", testOptions());
  } catch (const SceneError& e) {
    std::vector<std::string> out;
    for (const auto& d : e.diagnostics())
      if (d.severity == Diagnostic::Severity::Error) out.push_back(std::to_string(d.where.line) + ": " + d.message);
    return out;
  }
  return {};
}

}  // namespace

TEST_CASE("start overlaps: a robot inside the ground is an error at its line, naming the ground and its line",
          "[scene]") {
  for (const std::string engine : {"ode", "bullet"}) {
    INFO(engine);
    const auto errors = errorsOf("  <ground/>\n  <artifact name=\"r0\" type=\"crate\" xyz=\"1 2 0.05\"/>\n", engine);
    REQUIRE(errors.size() == 1);
    CHECK_THAT(errors[0], StartsWith("6: 'r0' starts 50.0 mm inside 'ground' (start.xml:5) at "));
    CHECK_THAT(errors[0], Contains("raise it so that it rests on the ground"));
    CHECK_THAT(errors[0], Contains("allow_overlap=\"true\" on the <artifact>"));
  }
}

TEST_CASE("start overlaps: resting on the ground, or sunk into it by less than a millimetre, is no overlap",
          "[scene]") {
  CHECK(errorsOf("  <ground/>\n  <artifact name=\"r0\" type=\"crate\" xyz=\"0 0 0.1\"/>\n").empty());
  CHECK(errorsOf("  <ground/>\n  <artifact name=\"r0\" type=\"crate\" xyz=\"0 0 0.0995\"/>\n").empty());
  // 2 mm in is reported
  const auto errors = errorsOf("  <ground/>\n  <artifact name=\"r0\" type=\"crate\" xyz=\"0 0 0.098\"/>\n");
  REQUIRE(errors.size() == 1);
  CHECK_THAT(errors[0], StartsWith("6: 'r0' starts 2.0 mm inside 'ground'"));
  // two crates side by side, touching
  CHECK(errorsOf("  <artifact name=\"a\" type=\"crate\" xyz=\"0 0 1\"/>\n"
                 "  <artifact name=\"b\" type=\"crate\" xyz=\"0.2 0 1\"/>\n")
            .empty());
}

TEST_CASE("start overlaps: two robots inside one another are reported at the later one's line", "[scene]") {
  const auto errors = errorsOf("  <artifact name=\"a\" type=\"crate\" xyz=\"0 0 1\"/>\n"
                               "  <artifact name=\"b\" type=\"ball\" xyz=\"0.12 0 1\"/>\n");
  REQUIRE(errors.size() == 1);
  // the ball's centre is 2 cm outside the crate's face: 3 cm of its 5 cm radius are inside
  CHECK_THAT(errors[0], StartsWith("6: 'b' starts 30.0 mm inside 'a' (start.xml:5) at "));
  CHECK_THAT(errors[0], Contains("move them apart"));
}

TEST_CASE("start overlaps: allow_overlap on either placement lets them start so", "[scene]") {
  CHECK(errorsOf("  <artifact name=\"a\" type=\"crate\" xyz=\"0 0 1\" allow_overlap=\"true\"/>\n"
                 "  <artifact name=\"b\" type=\"ball\" xyz=\"0.12 0 1\"/>\n")
            .empty());
  CHECK(errorsOf("  <obstacle name=\"dock\" xyz=\"0 0 1\" allow_overlap=\"true\"><box size=\"0.3 0.3 0.3\"/></obstacle>\n"
                 "  <artifact name=\"b\" type=\"ball\" xyz=\"0 0 1\"/>\n")
            .empty());
  CHECK(errorsOf("  <ground/>\n  <swarm type=\"crate\" count=\"4\" name=\"r{i}\" allow_overlap=\"true\"/>\n").empty());
  // and it is kept in the scene as XML
  const std::string xml = R"(<scene><type name="crate" file="crate.xml"/><ground/>
    <artifact name="r0" type="crate" allow_overlap="true"/></scene>)";
  const SceneModel model = parseSceneString(xml, "kept.xml", kData / "valid", testOptions());
  CHECK_THAT(model.toXml(), Contains("allow_overlap=\"true\""));
  CHECK(parseSceneString(model.toXml(), "again.xml", kData / "valid", testOptions()).placements.back().allow_overlap);
}

TEST_CASE("start overlaps: obstacles and the ground among themselves, and ghosts, are not checked", "[scene]") {
  // a wall sunk into the ground and crossing another: static shapes never push each other
  CHECK(errorsOf("  <ground/>\n"
                 "  <obstacle name=\"w1\" xyz=\"0 0 0\"><box size=\"4 0.2 1\"/></obstacle>\n"
                 "  <obstacle name=\"w2\" xyz=\"0 0 0\"><box size=\"0.2 4 1\"/></obstacle>\n")
            .empty());
  // a ghost is where a real robot's poses put it, not where it was placed
  CHECK(errorsOf("  <ground/>\n  <artifact name=\"g\" type=\"crate\"><ghost timeout=\"1\"/></artifact>\n").empty());
}

TEST_CASE("start overlaps: a swarm too tight for its members is reported three times, then counted", "[scene]") {
  const auto errors = errorsOf("  <swarm type=\"crate\" count=\"4\" name=\"r{i}\" spacing=\"0.1\" xyz=\"0 0 1\"/>\n");
  // 2 x 2 crates 10 cm apart: every one of the 6 pairs overlaps
  REQUIRE(errors.size() == 4);
  CHECK_THAT(errors[0], StartsWith("5: 'r1' starts 100.0 mm inside 'r0' (start.xml:5)"));
  CHECK_THAT(errors[0], Contains("allow_overlap=\"true\" on the <swarm>"));
  CHECK(errors[3] == "5: ... and 3 more overlaps between members of this <swarm>");
}

TEST_CASE("start overlaps: in document order with the scene's other errors", "[scene]") {
  const auto errors = errorsOf("  <ground/>\n  <artifact name=\"r0\" type=\"crate\"/>\n"
                               "  <artifact name=\"r1\" type=\"crate\" xyz=\"1 0 0\"/>\n"
                               "  <artifact name=\"r0\" type=\"crate\" xyz=\"2 0 1\"/>\n");
  // the duplicate name stops the build before any overlap is looked for: one problem at a time
  REQUIRE(errors.size() == 1);
  CHECK_THAT(errors[0], StartsWith("8: duplicate artifact name 'r0'"));
  const auto both = errorsOf("  <ground/>\n  <artifact name=\"r0\" type=\"crate\"/>\n"
                             "  <obstacle name=\"o\" xyz=\"5 0 0.5\"><box size=\"1 1 1\"/></obstacle>\n"
                             "  <artifact name=\"r1\" type=\"crate\" xyz=\"5 0 0.5\"/>\n");
  REQUIRE(both.size() == 2);
  CHECK_THAT(both[0], StartsWith("6: 'r0' starts 100.0 mm inside 'ground'"));
  CHECK_THAT(both[1], StartsWith("8: 'r1' starts 600.0 mm inside 'o'"));
}
