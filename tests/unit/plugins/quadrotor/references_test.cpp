// The references: trajectory files read and flown (hover, eights and formation: flight_test.cpp, tests/integration/).
#include "references.hpp"
#include "part_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace ssx;
using namespace ssx::quadrotor;
using namespace ssx::quadrotor::test;
namespace fs = std::filesystem;

TEST_CASE("a trajectory file: header, comments, an optional yaw column, zero-order hold", "[quadrotor][parts]") {
  const fs::path file = writeFile("ssx_parts_trajectory.csv", "t, x, y, z, yaw\n# a comment\n\n0, 0, 0, 1, 0\n"
                                                               "1.5, 1, 0, 1, 0.5\n3, 1, 1, 2, 1\n");
  const Trajectory t = Trajectory::read(file);
  REQUIRE(t.times.size() == 3);
  CHECK(t.yaws == std::vector<double>{0, 0.5, 1});
  CHECK(t.rowAt(-1) == 0);
  CHECK(t.rowAt(0) == 0);
  CHECK(t.rowAt(1.4999) == 0);
  CHECK(t.rowAt(1.5) == 1);
  CHECK(t.rowAt(100) == 2);
  CHECK(t.positions[2] == Vec3(1, 1, 2));
  const fs::path ragged = writeFile("ssx_parts_ragged.csv", "0, 0, 0, 1\n1, 1, 0, 1, 0.5\n");
  CHECK_THROWS_WITH(Trajectory::read(ragged), Catch::Contains("ssx_parts_ragged.csv:2: error: every trajectory row "
                                                              "has the same columns"));
  const fs::path words = writeFile("ssx_parts_words.csv", "0, 0, 0, 1\n1, one, 0, 1\n");
  CHECK_THROWS_WITH(Trajectory::read(words), Catch::Contains("ssx_parts_words.csv:2: error: a trajectory row"));
  CHECK_THROWS_WITH(Trajectory::read(fs::temp_directory_path() / "ssx_parts_none.csv"),
                    Catch::Contains("cannot read the trajectory file"));
}

TEST_CASE("a quadrotor flies a trajectory file, holding each row until the next", "[quadrotor][parts]") {
  const fs::path file = writeFile("ssx_parts_flight.csv", "t,x,y,z,yaw\n0,0,0,1,0\n4,1,0,1.5,0.5\n");
  Scene s = sceneOf(quad("q", "0 0 1", "reference=\"trajectory\" trajectory=\"" + file.string() + "\""));
  Environment& env = *s.environment;
  Artifact& q = *env.findArtifact("q");
  env.step(1900);  // 3.8 s: still on the first row
  CHECK((q.pose().position - Vec3(0, 0, 1)).norm() < 0.02);
  env.step(3000);  // 6 s on the second row
  CHECK((q.pose().position - Vec3(1, 0, 1.5)).norm() < 0.05);
  const Vec3 forward = q.pose().orientation * Vec3::UnitX();
  CHECK(std::atan2(forward.y(), forward.x()) == Approx(0.5).margin(0.03));  // its yaw is held
}
