// findShapeOverlaps (ode/ode_overlaps.cpp), seen through the scene check that uses it: the depth
// of each kind of shape pair, posed and turned as placed.
#include <ssx/ssx.hpp>

#include "scene_util.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace ssx;
using ssx::test::kData;
using ssx::test::testOptions;
using Catch::StartsWith;

namespace {

// the first error of a scene of crates (20 cm boxes) and balls (5 cm spheres), without its line
std::string firstOverlap(const std::string& body) {
  const std::string xml = "<scene>\n  <type name=\"crate\" file=\"crate.xml\"/>\n  <type name=\"ball\" file=\"ball.xml\"/>\n" +
                          body + "</scene>\n";
  try {
    (void)loadSceneFromString(xml, "shapes.xml", kData / "valid", testOptions());
  } catch (const SceneError& e) {
    for (const auto& d : e.diagnostics())
      if (d.severity == Diagnostic::Severity::Error) return d.message;
  }
  return "(none)";
}

}  // namespace

TEST_CASE("ode overlaps: each kind of shape pair, with its depth", "[ode][scene]") {
  // a ball 2 cm outside a cylinder's side: 3 cm of its 5 cm radius inside
  CHECK_THAT(firstOverlap("  <obstacle name=\"post\" xyz=\"0.12 0 1\"><cylinder radius=\"0.1\" length=\"0.5\"/></obstacle>\n"
                          "  <artifact name=\"b\" type=\"ball\" xyz=\"0 0 1\"/>\n"),
             StartsWith("'b' starts 30.0 mm inside 'post'"));
  // a ball 8 cm from a capsule's axis of radius 5 cm
  CHECK_THAT(firstOverlap("  <obstacle name=\"pill\" xyz=\"0.08 0 1\"><capsule radius=\"0.05\" length=\"0.4\"/></obstacle>\n"
                          "  <artifact name=\"b\" type=\"ball\" xyz=\"0 0 1\"/>\n"),
             StartsWith("'b' starts 20.0 mm inside 'pill'"));
  // a crate's face 5 cm into a sphere of 10 cm
  CHECK_THAT(firstOverlap("  <obstacle name=\"dome\" xyz=\"0 0 1\"><sphere radius=\"0.1\"/></obstacle>\n"
                          "  <artifact name=\"c\" type=\"crate\" xyz=\"0.15 0 1\"/>\n"),
             StartsWith("'c' starts 50.0 mm inside 'dome'"));
  // a crate turned 45 degrees about x, its centre 10 cm up: its lowest edge 41.4 mm in the ground
  CHECK_THAT(firstOverlap("  <ground/>\n  <artifact name=\"c\" type=\"crate\" xyz=\"0 0 0.1\" rpy=\"0.7853981634 0 0\"/>\n"),
             StartsWith("'c' starts 41.4 mm inside 'ground'"));
  // a box obstacle turned about z: a crate sunk 5 cm into its top
  CHECK_THAT(firstOverlap("  <obstacle name=\"box\" rpy=\"0 0 0.5\" xyz=\"0 0 0.5\"><box size=\"1 1 1\"/></obstacle>\n"
                          "  <artifact name=\"c\" type=\"crate\" xyz=\"0 0 1.05\"/>\n"),
             StartsWith("'c' starts 50.0 mm inside 'box'"));
}
