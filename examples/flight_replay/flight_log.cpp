#include "flight_log.hpp"

#include <ssx/error.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace ssx::flight {

namespace {

constexpr std::array<const char*, 12> kColumns = {"t",    "px",   "py",   "pz",   "roll",       "pitch",
                                                  "yaw",  "sp_x", "sp_y", "sp_z", "cmd_thrust", "vbat"};

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
  std::array<std::size_t, kColumns.size()> at{};
  for (std::size_t c = 0; c < kColumns.size(); ++c) {
    const auto it = std::find(header.begin(), header.end(), kColumns[c]);
    if (it == header.end())
      throw errorAt(file, 1, std::string("no column '") + kColumns[c] +
                                 "' in the header (a NanoBench log: t, px, py, pz, roll, pitch, yaw, sp_x, sp_y, sp_z, cmd_thrust, vbat)");
    at[c] = static_cast<std::size_t>(it - header.begin());
  }
  Log log;
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = split(line);
    std::array<double, kColumns.size()> v{};
    for (std::size_t c = 0; c < kColumns.size(); ++c) {
      if (at[c] >= cells.size()) throw errorAt(file, number, std::string("no value for '") + kColumns[c] + "'");
      const std::string& cell = cells[at[c]];
      char* end = nullptr;
      errno = 0;
      v[c] = std::strtod(cell.c_str(), &end);
      if (cell.empty() || end != cell.c_str() + cell.size() || errno != 0 || !std::isfinite(v[c]))
        throw errorAt(file, number, std::string("'") + kColumns[c] + "' is '" + cell + "', not a finite number");
    }
    const Row r{v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11]};
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
  if (up.size() < 100)
    throw Error(label + ": error: fewer than 100 rows (1 s) of flight at cruise altitude (" + std::to_string(cruise) +
                " m): give the take-off mass with --mass KG");
  return median(up, 0, up.size());
}

}  // namespace ssx::flight
