#include "flight_log.hpp"

#include <ssx/error.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

namespace ssx::flight {

namespace {

// A column of Row: its name in the trimmed copies, its name in the dataset's own files, and
// whether a log must have it.
struct Column {
  const char* name;
  const char* source_name;
  bool required;
};
constexpr std::array<Column, 17> kColumns = {{{"t", "t", true},
                                              {"px", "px", true},
                                              {"py", "py", true},
                                              {"pz", "pz", true},
                                              {"roll", "roll", true},
                                              {"pitch", "pitch", true},
                                              {"yaw", "yaw", true},
                                              {"sp_x", "sp_ctrltarget_x", true},
                                              {"sp_y", "sp_ctrltarget_y", true},
                                              {"sp_z", "sp_ctrltarget_z", true},
                                              {"cmd_thrust", "pid_controller_cmd_thrust", true},
                                              {"vbat", "pwr_pm_vbat", true},
                                              {"vz", "vz", false},
                                              {"m1", "motor_motor_m1", false},
                                              {"m2", "motor_motor_m2", false},
                                              {"m3", "motor_motor_m3", false},
                                              {"m4", "motor_motor_m4", false}}};
constexpr std::size_t kUsed = kColumns.size();
constexpr std::size_t kAbsent = static_cast<std::size_t>(-1);

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

Error errorAt(const std::filesystem::path& file, std::size_t line, const std::string& what) {
  return Error(file.string() + ":" + std::to_string(line) + ": error: " + what);
}

}  // namespace

Log readLog(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": error: cannot read it");
  std::string line;
  if (!std::getline(in, line)) throw errorAt(file, 1, "empty: a header row (t,px,py,pz,...) comes first");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const auto header = split(line);
  std::array<std::size_t, kUsed> at{};
  for (std::size_t c = 0; c < kUsed; ++c) {
    auto it = std::find(header.begin(), header.end(), kColumns[c].name);
    if (it == header.end()) it = std::find(header.begin(), header.end(), kColumns[c].source_name);
    if (it == header.end() && kColumns[c].required)
      throw errorAt(file, 1, std::string("no column '") + kColumns[c].name +
                                 "' in the header (a NanoBench log: t, px, py, pz, roll, pitch, yaw, sp_x, sp_y, sp_z, "
                                 "cmd_thrust, vbat, as in the trimmed copies or as the dataset names them)");
    at[c] = it == header.end() ? kAbsent : static_cast<std::size_t>(it - header.begin());
  }
  Log log;
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = split(line);
    std::array<double, kUsed> v{};
    for (std::size_t c = 0; c < kUsed; ++c) {
      v[c] = std::numeric_limits<double>::quiet_NaN();
      if (at[c] == kAbsent) continue;
      if (at[c] >= cells.size()) throw errorAt(file, number, std::string("no value for '") + kColumns[c].name + "'");
      const std::string& cell = cells[at[c]];
      char* end = nullptr;
      errno = 0;
      v[c] = std::strtod(cell.c_str(), &end);
      if (cell.empty() || end != cell.c_str() + cell.size() || errno != 0 || !std::isfinite(v[c]))
        throw errorAt(file, number, std::string("'") + kColumns[c].name + "' is '" + cell + "', not a finite number");
    }
    const Row r{v[0], v[1], v[2],  v[3],  v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11],
                v[12], {v[13], v[14], v[15], v[16]}};
    if (!log.rows.empty() && !(r.t > log.rows.back().t))
      throw errorAt(file, number, "t does not increase (" + std::to_string(r.t) + " s after " +
                                      std::to_string(log.rows.back().t) + " s)");
    log.rows.push_back(r);
    log.vbat.push_back(r.vbat);
  }
  if (log.rows.size() < 2) throw Error(file.string() + ": error: fewer than two rows of data");
  return log;
}

Segment findFlight(const Log& log, const std::string& label) {
  auto flying = [](const Row& r) { return r.sp_x != 0 || r.sp_y != 0 || r.sp_z != 0; };
  const auto first = std::find_if(log.rows.begin(), log.rows.end(), flying);
  if (first == log.rows.end()) throw Error(label + ": error: every set-point is zero: the vehicle never took off");
  const auto last = std::find_if(log.rows.rbegin(), log.rows.rend(), flying);
  return {static_cast<std::size_t>(first - log.rows.begin()),
          static_cast<std::size_t>(log.rows.rend() - last) - 1};
}

double median(const std::vector<double>& values, std::size_t first, std::size_t last) {
  std::vector<double> v(values.begin() + static_cast<std::ptrdiff_t>(first), values.begin() + static_cast<std::ptrdiff_t>(last));
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  return (*mid + *std::max_element(v.begin(), mid)) / 2;
}

double cruiseThrustCommand(const Log& log, const Segment& flight, const std::string& label) {
  const auto& rows = log.rows;
  std::vector<double> heights;
  for (std::size_t i = flight.first; i <= flight.last; ++i) heights.push_back(rows[i].sp_z);
  const double cruise = median(heights, 0, heights.size());
  std::vector<double> up;
  for (std::size_t i = flight.first; i <= flight.last; ++i) {
    const Row& r = rows[i];
    if (std::abs(r.sp_z - cruise) <= 0.01 && r.pz > cruise / 2 && r.cmd_thrust > 0)
      up.push_back(r.cmd_thrust * std::cos(r.roll) * std::cos(r.pitch));
  }
  if (up.size() < 100 || up.size() < (flight.last + 1 - flight.first) / 2)
    throw Error(label + ": error: " + std::to_string(up.size()) + " rows of level flight at cruise altitude (" +
                std::to_string(cruise) + " m): fewer than 100 (1 s) or than half the flight's; give the take-off mass with --mass KG");
  return median(up, 0, up.size());
}

namespace {

// the propellers' thrust-voltage curve (the firmware's 2.1+ set, as the crazyflie preset's), N
double propellerThrust(double volts) {
  return -0.024765 + volts * (0.065238 + volts * (-0.026793 + volts * 0.0067768));
}

}  // namespace

std::array<double, 4> rotorThrustFactors(const Log& log, const Segment& flight, const std::string& label) {
  const auto& rows = log.rows;
  const double rest = rows[flight.first].pz;
  std::array<double, 4> sum{};
  std::size_t n = 0;
  for (std::size_t i = flight.first; i <= flight.last; ++i) {
    const Row& r = rows[i];
    if (!(r.pz > rest + 0.1)) continue;
    bool usable = true;
    for (const double pwm : r.motor) usable = usable && std::isfinite(pwm) && pwm > 0 && pwm < 65000;
    if (!usable) continue;
    for (std::size_t k = 0; k < 4; ++k) sum[k] += propellerThrust(r.motor[k] / 65535.0 * r.vbat);
    ++n;
  }
  if (n < 100)
    throw Error(label + ": error: the motors' shares cannot be found: fewer than 100 rows 0.1 m above the ground with "
                        "m1-m4 logged and none at full PWM");
  const double mean = (sum[0] + sum[1] + sum[2] + sum[3]) / 4;
  std::array<double, 4> factors{};
  for (std::size_t k = 0; k < 4; ++k) factors[k] = mean / sum[k];
  return factors;
}

MassEstimate identifyMass(const Log& log, const Segment& flight, const std::string& label, const std::string& method) {
  constexpr double kGravity = 9.81, kThrustMax = 0.12;
  const auto& rows = log.rows;
  if (method != "balance") {
    try {
      const double u = cruiseThrustCommand(log, flight, label);
      char how[160];
      std::snprintf(how, sizeof how, "thrust command %.0f in level flight", u);
      return {4 * kThrustMax * u / 65535.0 / kGravity, how};
    } catch (const Error&) {
      if (method == "cruise") throw;
      // no level flight: the vertical force balance over the whole flight, below
    }
  }
  const double rest = rows[flight.first].pz;
  constexpr std::size_t kHalf = 10;  // rows either side for the vertical acceleration (0.1 s at 100 Hz)
  std::vector<double> masses;
  for (std::size_t i = std::max(flight.first, kHalf); i <= flight.last && i + kHalf < rows.size(); ++i) {
    const Row& r = rows[i];
    if (!(r.pz > rest + 0.1) || !std::isfinite(r.vz)) continue;
    double up = 0;
    bool motors = true;
    for (const double pwm : r.motor) {
      if (!std::isfinite(pwm)) motors = false;
      if (pwm > 0) up += propellerThrust(pwm / 65535.0 * r.vbat);
    }
    const double az = (rows[i + kHalf].vz - rows[i - kHalf].vz) / (rows[i + kHalf].t - rows[i - kHalf].t);
    if (!motors || !std::isfinite(az) || up <= 0) continue;
    masses.push_back(up * std::cos(r.roll) * std::cos(r.pitch) / (kGravity + az));
  }
  if (masses.size() < 100)
    throw Error(label + ": error: the take-off mass cannot be found: fewer than 1 s of level flight at cruise "
                        "altitude, and fewer than 100 rows 0.1 m above the ground with vz and the motors' m1-m4 "
                        "logged: give it with --mass KG");
  char how[160];
  std::snprintf(how, sizeof how, "motors' thrust over %zu airborne rows against g + the vertical acceleration",
                masses.size());
  return {median(masses, 0, masses.size()), how};
}

}  // namespace ssx::flight
