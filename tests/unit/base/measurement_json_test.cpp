// A measurement's JSON appended in place (base/measurement_json.hpp): what measurementJson returns,
// after whatever the string held, and nothing appended for a kind without JSON.
#include "base/measurement_json.hpp"

#include <ssx/environment.hpp>
#include <ssx/measurements.hpp>

#include <catch2/catch.hpp>

#include <string>

using namespace ssx;

TEST_CASE("measurement JSON appended in place: the same text as measurementJson after what was there",
          "[measurements]") {
  const Environment env;
  PoseMeasurement pose;
  pose.stamp = 250'000'000;
  pose.pose.position = Vec3(1, -2, 0.5);
  pose.linear_velocity = Vec3(0, 0, -1);
  std::string out = R"({"0":)";
  REQUIRE(detail::appendMeasurementJson(out, pose, env));
  CHECK(out == R"({"0":)" + measurementJson(pose, env));
  CHECK(out.find(R"("kind":"pose","stamp":0.25,"position":[1,-2,0.5],"orientation":[1,0,0,0])") != std::string::npos);
  CHECK(out.back() == '}');
  // a clock has no JSON: nothing appended, false
  const std::size_t before = out.size();
  CHECK_FALSE(detail::appendMeasurementJson(out, ClockMeasurement{}, env));
  CHECK(out.size() == before);
}
