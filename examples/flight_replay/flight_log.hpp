#pragma once
// A real flight's log in NanoBench's format (examples/fidelity_nanobench/data/README.md), read and
// checked, and what ssx_flight_replay finds in it.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace ssx::flight {

struct Row {
  double t, px, py, pz, roll, pitch, yaw, sp_x, sp_y, sp_z, cmd_thrust, vbat;
};

struct Log {
  std::vector<Row> rows;
  std::vector<double> vbat;  // the rows' battery voltages (for medians)
};

/// Reads the columns named in Row (any order; others ignored) from a CSV file with a header.
/// ssx::Error "FILE:LINE: error: ..." for a missing column, a value that is not a finite number, a
/// time that does not increase, or fewer than two rows.
Log readLog(const std::filesystem::path& file);

/// The rows of the flight, both included.
struct Segment {
  std::size_t first = 0, last = 0;
};

/// From take-off (the first set-point that is not all zeros: the log's set-points are zero while
/// the motors are off) to the last such set-point. ssx::Error naming `label` if there is none.
Segment findFlight(const Log& log, const std::string& label);

/// The thrust command that holds the vehicle up in level flight: the median over the flight at
/// cruise altitude (the set-point within 1 cm of the median set-point height, the vehicle above half
/// of it) of the thrust command times the cosine of the roll and of the pitch (what of it points
/// up). ssx::Error naming `label` when the log has fewer than 100 such rows.
double cruiseThrustCommand(const Log& log, const Segment& flight, const std::string& label);

/// The median of values[first, last).
double median(const std::vector<double>& values, std::size_t first, std::size_t last);

}  // namespace ssx::flight
