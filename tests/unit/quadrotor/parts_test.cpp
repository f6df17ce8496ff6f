// The quadrotor's parts alone (a vehicle without effects or controller, the wind without a
// vehicle, a trajectory file) and in a scene (the scene's <wind>, a trajectory reference).
#include "effects.hpp"
#include "references.hpp"
#include "vehicle.hpp"

#include <ssx/ssx.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

using namespace ssx;
using namespace ssx::quadrotor;
namespace fs = std::filesystem;

namespace {

const fs::path kArtifacts = fs::path(SSX_EXAMPLES_DIR) / "artifacts";

Scene sceneOf(const std::string& body, std::uint64_t seed = 1) {
  return loadSceneFromString("<scene><environment timestep=\"0.002\" seed=\"" + std::to_string(seed) +
                                 "\"/><ground/><type name=\"q\" file=\"mk_quad.xml\"/>"
                                 "<type name=\"box\" file=\"box.xml\"/>" +
                                 body + "</scene>",
                             "parts.xml", kArtifacts);
}

// a plus-configuration of four rotors 0.225 m from the centre, as the mk_quad's
std::vector<Rotor> plus() {
  return {{Vec3(0.225, 0, 0), 1}, {Vec3(0, 0.225, 0), -1}, {Vec3(-0.225, 0, 0), 1}, {Vec3(0, -0.225, 0), -1}};
}

// an mk_quad with noiseless sensors, so that what moves it is what the test sets
std::string quad(const std::string& name, const std::string& xyz, const std::string& driver = "") {
  return "<artifact name=\"" + name + "\" type=\"q\" xyz=\"" + xyz + "\"><driver " + driver +
         "/><sensor index=\"0\" noise=\"false\"/><sensor index=\"1\" position_noise=\"0\" velocity_noise=\"0\"/>"
         "</artifact>";
}

fs::path writeFile(const std::string& name, const std::string& text) {
  const fs::path path = fs::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("a vehicle alone: its rotors at the hover speed carry a body of its weight", "[quadrotor][parts]") {
  // a 1 kg box with no driver; the test spins the vehicle's rotors and applies its wrench each step
  Scene s = sceneOf("<artifact name=\"b\" type=\"box\" xyz=\"0 0 2\"/>");
  Environment& env = *s.environment;
  env.start();
  Artifact& box = *env.findArtifact("b");
  const RotorParams rp = *preset("mk_quad");
  const double g = -env.settings().physics.gravity.z();
  for (double factor : {1.0, 1.05}) {
    Vehicle vehicle;
    vehicle.configure(RotorModel(plus(), rp), Vec3::Zero(), std::nullopt);
    const double hover = std::sqrt(1.0 * g / (4 * rp.thrust_coefficient));
    const std::vector<double> speeds(4, factor * hover);
    vehicle.spinAt(speeds);
    const double z0 = box.pose().position.z();
    for (int i = 0; i < 500; ++i) {  // 1 s
      vehicle.stepMotors(0.002, speeds);
      const BodyState state = box.root().state();
      vehicle.applyWrench(box.root(), state, env.bodyState(box.root().bodyIndex()), Vec3::Zero());
      env.step();
    }
    const double climbed = box.pose().position.z() - z0;
    // 5 % more speed is 10.25 % more thrust: about 0.5 * 1.0 m/s^2 in 1 s (less the rotor drag)
    INFO("speed factor " << factor << " climbed " << climbed << " m");
    if (factor == 1.0)
      CHECK(std::abs(climbed) < 0.005);
    else
      CHECK(climbed == Approx(0.5 * 0.1025 * g).epsilon(0.1));
    CHECK(box.pose().position.head<2>().norm() < 1e-6);  // a symmetric vehicle in still air stays put
  }
}

TEST_CASE("the wind alone: the mean, and a gust that rises and falls as 1 - cos", "[quadrotor][parts]") {
  WindParams p;
  p.mean = Vec3(2, 0, 0);
  p.gust = Vec3(0, 3, 0);
  p.gust_start = 1;
  p.gust_duration = 2;
  Wind wind;
  wind.configure(p, 0.0);
  REQUIRE(wind.active());
  Random random(1);
  CHECK(wind.air(0.5, 0.01, Vec3(0, 0, 1), Vec3::Zero(), random) == Vec3(2, 0, 0));
  CHECK(wind.air(2.0, 0.01, Vec3(0, 0, 1), Vec3::Zero(), random).isApprox(Vec3(2, 3, 0), 1e-12));  // its peak
  CHECK(wind.air(1.5, 0.01, Vec3(0, 0, 1), Vec3::Zero(), random).isApprox(Vec3(2, 1.5, 0), 1e-12));
  CHECK(wind.air(3.5, 0.01, Vec3(0, 0, 1), Vec3::Zero(), random) == Vec3(2, 0, 0));
  Wind calm;
  calm.configure(WindParams{}, 0.0);
  CHECK_FALSE(calm.active());
}

TEST_CASE("the scene's wind pushes every quadrotor downwind; an artifact's own wind overrides it",
          "[quadrotor][parts]") {
  Scene s = sceneOf("<wind mean=\"4 0 0\"/>" + quad("a", "0 0 1") + quad("b", "0 3 1") +
                    quad("calm", "0 6 1", "wind=\"0 0 0\""));
  Environment& env = *s.environment;
  CHECK(env.settings().wind.mean == Vec3(4, 0, 0));
  env.step(250);  // 0.5 s: the position loop has not caught the drift yet
  const double a = env.findArtifact("a")->pose().position.x();
  const double b = env.findArtifact("b")->pose().position.x();
  const double calm = env.findArtifact("calm")->pose().position.x();
  INFO("downwind: a " << a << " m, b " << b << " m, calm " << calm << " m");
  CHECK(a > 0.005);
  CHECK(b == a);  // without turbulence the same wind moves them alike
  CHECK(std::abs(calm) < 1e-6);
}

TEST_CASE("the scene's turbulence is each robot's own, and the same again from the same seed", "[quadrotor][parts]") {
  const auto run = [](std::uint64_t seed) {
    Scene s = sceneOf("<wind turbulence_w20=\"7.7\"/>" + quad("a", "0 0 1") + quad("b", "0 3 1"), seed);
    s.environment->step(1000);
    const Vec3 a = s.environment->findArtifact("a")->pose().position;
    const Vec3 b = s.environment->findArtifact("b")->pose().position - Vec3(0, 3, 0);
    return std::pair(a, b);
  };
  const auto [a, b] = run(1);
  INFO("a moved " << (a - Vec3(0, 0, 1)).transpose() << ", b " << (b - Vec3(0, 0, 1)).transpose());
  CHECK((a - Vec3(0, 0, 1)).norm() > 1e-3);  // it felt turbulence
  CHECK((a - b).norm() > 1e-3);              // not the same as its neighbour's
  const auto [a2, b2] = run(1);
  CHECK(a2 == a);
  CHECK(b2 == b);
}

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
