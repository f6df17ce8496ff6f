// ssx_flight_replay: flies a real Crazyflie flight again in simulation, from its log.
//
// Reads a log in NanoBench's format (the columns of examples/fidelity_nanobench/data/README.md;
// t, px, py, pz, roll, pitch, yaw, sp_x, sp_y, sp_z, cmd_thrust and vbat are used), starts the installed
// `crazyflie` (its firmware's PID cascade) where the log's vehicle stands, gives it each logged
// set-point at the simulated time the firmware received it (held until the next), and writes
//   t,px,py,pz,sp_x,sp_y,sp_z,vx,vy,vz,roll,pitch,yaw
// on the log's own time axis, from take-off (the first set-point that is not all zeros) to the
// last such set-point.
//
// Identified from the log, and printed (nothing is fitted to the tracking error):
// - the take-off mass (flight_log.hpp, identifyMass): the thrust command that holds the vehicle up
//   in level flight at cruise altitude through the firmware's thrust model (u / 65535 x 0.12 N a
//   motor), m = 4 x 0.12 u / 65535 / g; a flight without 1 s of level flight (helix, trefoil, ramp):
//   the motors' thrust against g plus the vertical acceleration over the whole airborne flight
//   (--mass KG instead gives it);
// - the battery voltage the firmware's compensation sees: the median logged voltage in flight;
// - the vertical offset between the log's tracked point (motion-capture markers) and the
//   simulated centre of mass: the log's height at rest minus the simulated vehicle's.
//
// usage: ssx_flight_replay LOG.csv --out SIM.csv [--mass KG | --mass-from auto|cruise|balance]
//                          [--battery median|log] [--rotor-factors none|log] [--physics ode|bullet]
//                          [--artifact FILE] [--inertia-scale S] [--driver KEY=VALUE]... [--sensor KEY=VALUE]...
// --driver and --sensor set the crazyflie's driver and pose-sensor parameters (the sweep over
// unpublished values: time_constant_up=..., delay=...); --artifact flies another artifact file.
#include "flight_log.hpp"

#include <ssx/ssx.hpp>

#include <CLI/CLI.hpp>
#include <pugixml.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;

namespace {

// roll, pitch, yaw (rad; z-y-x) of an orientation
ssx::Vec3 rollPitchYaw(const ssx::Quat& q) {
  return {std::atan2(2 * (q.w() * q.x() + q.y() * q.z()), 1 - 2 * (q.x() * q.x() + q.y() * q.y())),
          std::asin(std::clamp(2 * (q.w() * q.y() - q.z() * q.x()), -1.0, 1.0)),
          std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()))};
}

struct Options {
  fs::path log, out, artifact;
  double mass = 0;  // 0: from the log
  std::string mass_from = "auto";
  std::string battery = "median";  // or "log": the logged voltage row by row
  std::string rotor_factors = "none";  // or "log": each rotor's thrust from the motors' shares
  double inertia_scale = 1;
  std::string physics;
  std::vector<std::string> driver, sensor;
};

// KEY=VALUE into an attribute of `node` (an error names the option)
void setAttribute(pugi::xml_node node, const std::string& option, const std::string& kv) {
  const auto eq = kv.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ssx::Error(option + " '" + kv + "': give KEY=VALUE (a parameter of the crazyflie's " + option.substr(2) + ")");
  const std::string key = kv.substr(0, eq);
  if (!node.attribute(key.c_str())) node.append_attribute(key.c_str());
  node.attribute(key.c_str()).set_value(kv.substr(eq + 1).c_str());
}

// The artifact file with the identified mass and the options' parameters, in a private directory
// that is removed when this goes away.
class ArtifactCopy {
 public:
  ArtifactCopy(const Options& o, double mass) {
    pugi::xml_document doc;
    if (const auto r = doc.load_file(o.artifact.c_str()); !r)
      throw ssx::Error(o.artifact.string() + ": error: " + r.description());
    pugi::xml_node artifact = doc.child("artifact");
    pugi::xml_node body = artifact.child("physic");
    if (!body || !body.attribute("mass")) throw ssx::Error(o.artifact.string() + ": error: no root <physic> with a mass");
    body.attribute("mass").set_value(mass);
    if (o.inertia_scale != 1) {
      double i[3];
      if (std::sscanf(body.attribute("inertia").as_string(), "%lf %lf %lf", &i[0], &i[1], &i[2]) != 3)
        throw ssx::Error(o.artifact.string() + ": error: --inertia-scale needs the root <physic>'s inertia=\"IXX IYY IZZ\"");
      char scaled[128];
      std::snprintf(scaled, sizeof scaled, "%.9g %.9g %.9g", i[0] * o.inertia_scale, i[1] * o.inertia_scale,
                    i[2] * o.inertia_scale);
      body.attribute("inertia").set_value(scaled);
    }
    pugi::xml_node driver = artifact.child("driver");
    pugi::xml_node pose = artifact.find_child_by_attribute("sensor", "plugin", "pose");
    if (!driver || !pose) throw ssx::Error(o.artifact.string() + ": error: needs a <driver> and a pose <sensor>");
    driver.append_attribute("reference").set_value("external");
    for (const auto& kv : o.driver) setAttribute(driver, "--driver", kv);
    for (const auto& kv : o.sensor) setAttribute(pose, "--sensor", kv);
    dir_ = fs::temp_directory_path() / ("ssx_flight_replay_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    if (!doc.save_file((dir_ / "vehicle.xml").c_str())) throw ssx::Error("cannot write " + (dir_ / "vehicle.xml").string());
  }
  ~ArtifactCopy() {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  ArtifactCopy(const ArtifactCopy&) = delete;
  ArtifactCopy& operator=(const ArtifactCopy&) = delete;
  const fs::path& dir() const { return dir_; }

 private:
  fs::path dir_;
};

int replay(const Options& o) {
  const ssx::flight::Log log = ssx::flight::readLog(o.log);
  const ssx::flight::Segment flight = ssx::flight::findFlight(log, o.log.string());
  const ssx::flight::MassEstimate found =
      o.mass > 0 ? ssx::flight::MassEstimate{o.mass, "given: --mass"} : ssx::flight::identifyMass(log, flight, o.log.string(), o.mass_from);
  const double mass = found.kg;
  const double volts = ssx::flight::median(log.vbat, flight.first, flight.last + 1);
  const auto& start = log.rows[flight.first];
  std::printf("flight %.2f-%.2f s; %s: take-off mass %.1f g; battery %.3f V\n", start.t - log.rows.front().t,
              log.rows[flight.last].t - log.rows.front().t, found.how.c_str(), mass * 1e3, volts);

  Options options = o;
  if (o.rotor_factors == "log") {
    try {
      const auto k = ssx::flight::rotorThrustFactors(log, flight, o.log.string());
      char factors[160];
      std::snprintf(factors, sizeof factors, "%.4f %.4f %.4f %.4f", k[0], k[1], k[2], k[3]);
      std::printf("rotor thrust factors %s (from the motors' shares)\n", factors);
      options.driver.push_back(std::string("rotor_thrust_factors=") + factors);
    } catch (const ssx::Error& e) {
      // a flight whose motors were never below full PWM in the air (the ramp) has no shares to read:
      // it flies as the others, and says so
      std::string what = e.what();
      const auto at = what.find("error: ");
      if (at != std::string::npos) what.replace(at, 7, "warning: ");
      std::fprintf(stderr, "%s; flown with even rotors\n", what.c_str());
    }
  }
  ArtifactCopy copy(options, mass);
  const double battery_volts = std::clamp(volts, 2.0, 4.35);
  // the vehicle rests where the log's stands: its centre of mass at rest height, on the log's x, y and yaw
  const double rest_z = 0.01;  // the installed crazyflie's box, 0.02 m high
  std::string xml = "<scene><environment timestep=\"0.002\" seed=\"1\"/>";
  if (!o.physics.empty()) xml += "<physics engine=\"" + o.physics + "\"/>";
  char place[512];
  std::snprintf(place, sizeof place,
                "<type name=\"cf\" file=\"vehicle.xml\"/><ground/><artifact name=\"cf\" type=\"cf\" xyz=\"%.6f %.6f %.6f\" "
                "rpy=\"0 0 %.6f\"><driver crazyflie_battery_volts=\"%.4f\"/></artifact></scene>",
                start.px, start.py, rest_z, start.yaw, battery_volts);
  xml += place;
  ssx::Scene scene = ssx::loadSceneFromString(xml, o.log.string(), copy.dir());
  for (const auto& w : scene.warnings) std::fprintf(stderr, "%s\n", w.str().c_str());
  scene.files.addInput(o.log);
  if (const std::string wrong = scene.files.claimOutput(o.out, "--out"); !wrong.empty()) throw ssx::Error(wrong);
  const double z_offset = start.pz - rest_z;  // the markers above the centre of mass
  std::printf("markers %.1f mm above the centre of mass\n", z_offset * 1e3);

  ssx::Environment& env = *scene.environment;
  ssx::Artifact& cf = *env.findArtifact("cf");
  auto* input = dynamic_cast<ssx::SetpointInterface*>(cf.driver());
  if (input == nullptr) throw ssx::Error(o.artifact.string() + ": its driver takes no set-points");
  env.start();

  std::ofstream out(o.out);
  if (!out) throw ssx::Error("cannot write --out '" + o.out.string() + "'");
  out << "t,px,py,pz,sp_x,sp_y,sp_z,vx,vy,vz,roll,pitch,yaw\n";
  const double dt = ssx::toSeconds(env.timestep());
  for (std::size_t i = flight.first; i <= flight.last; ++i) {
    const auto& r = log.rows[i];
    // the simulation catches up with the log's clock, then takes this row's set-point
    const auto target = static_cast<std::int64_t>(std::llround((r.t - start.t) / dt));
    if (target > env.stepCount()) env.step(target - env.stepCount());
    ssx::Setpoint sp;
    sp.position = ssx::Vec3(r.sp_x, r.sp_y, r.sp_z - z_offset);
    sp.yaw = start.yaw;
    input->setSetpoint(sp);
    if (o.battery == "log") env.vary(cf, "battery_volts", std::clamp(r.vbat - battery_volts, -2.0, 0.5));
    const ssx::BodyState& s = cf.state();
    const ssx::Vec3 rpy = rollPitchYaw(s.pose.orientation);
    char line[400];
    std::snprintf(line, sizeof line, "%.3f,%.5f,%.5f,%.5f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.5f,%.5f,%.5f\n", r.t,
                  s.pose.position.x(), s.pose.position.y(), s.pose.position.z() + z_offset, r.sp_x, r.sp_y, r.sp_z,
                  s.linear_velocity.x(), s.linear_velocity.y(), s.linear_velocity.z(), rpy.x(), rpy.y(), rpy.z());
    out << line;
  }
  out.close();
  if (!out) throw ssx::Error("writing --out '" + o.out.string() + "' failed");
  std::printf("wrote %zu rows to %s\n", flight.last - flight.first + 1, o.out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Flies a real Crazyflie flight (a NanoBench log) again in simulation, from its logged set-points."};
  app.add_option("log", o.log, "the flight's log (NanoBench's columns)")->required()->check(CLI::ExistingFile);
  app.add_option("--out", o.out, "the simulated flight: t,px,py,pz,sp_x,sp_y,sp_z,vx,vy,vz,roll,pitch,yaw")->required();
  app.add_option("--mass", o.mass, "take-off mass, kg (default: from the log's hover thrust)")
      ->check(CLI::Range(0.005, 0.2));
  app.add_option("--mass-from", o.mass_from,
                 "how the mass is found: auto (level flight, else the force balance), cruise or balance")
      ->check(CLI::IsMember({"auto", "cruise", "balance"}));
  app.add_option("--battery", o.battery,
                 "the battery voltage the firmware and the motors get: median (the flight's median, held) or log "
                 "(the logged voltage row by row: its sag under load and over the flight)")
      ->check(CLI::IsMember({"median", "log"}));
  app.add_option("--rotor-factors", o.rotor_factors,
                 "none (the model's symmetric rotors) or log (each rotor's thrust factor from the motors' shares in the "
                 "log: rotor_thrust_factors)")
      ->check(CLI::IsMember({"none", "log"}));
  app.add_option("--inertia-scale", o.inertia_scale, "the vehicle's inertia times this (a guess's range)")
      ->check(CLI::Range(0.25, 4.0));
  app.add_option("--physics", o.physics, "physics engine")->check(CLI::IsMember({"ode", "bullet"}));
  o.artifact = ssx::installedDataDirectory() / "artifacts" / "crazyflie.xml";
  app.add_option("--artifact", o.artifact, "the vehicle (default: the installed crazyflie)")
      ->check(CLI::ExistingFile);
  app.add_option("--driver", o.driver, "KEY=VALUE: a parameter of its driver (repeatable)");
  app.add_option("--sensor", o.sensor, "KEY=VALUE: a parameter of its pose sensor (repeatable)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return replay(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ssx_flight_replay: %s\n", e.what());
    return 1;
  }
}
