#pragma once
// A real flight's log in NanoBench's format (examples/fidelity_nanobench/data/README.md), read and
// checked, and what ssx_flight_replay finds in it.
#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace ssx::flight {

struct Row {
  double t, px, py, pz, roll, pitch, yaw, sp_x, sp_y, sp_z, cmd_thrust, vbat;
  double vz;                  // NaN when the log has no vertical velocity
  double motor[4];            // the motors' PWM (0-65535), NaN when the log has none
};

struct Log {
  std::vector<Row> rows;
  std::vector<double> vbat;  // the rows' battery voltages (for medians)
};

/// Reads the columns named in Row (any order; others ignored) from a CSV file with a header: the
/// trimmed copies' names (sp_x, cmd_thrust, m1, vbat, ...) or the dataset's own (sp_ctrltarget_x,
/// pid_controller_cmd_thrust, motor_motor_m1, pwr_pm_vbat, ...). vz and the motors may be absent.
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
/// up). ssx::Error naming `label` when the log has fewer than 100 such rows (1 s) or when they are
/// under half of the flight's rows (a trefoil's height crosses its median now and then: that is
/// not level flight).
double cruiseThrustCommand(const Log& log, const Segment& flight, const std::string& label);

/// How the take-off mass was found.
struct MassEstimate {
  double kg = 0;
  std::string how;  // what it came from, for the user
};

/// The take-off mass from the thrust the vehicle flew with, through the firmware's thrust model
/// (u / 65535 x 0.12 N a motor; the propellers' thrust-voltage curve for the motors' PWM):
/// - level flight at cruise altitude, when at least 1 s and half the flight is: the thrust command
///   that holds the vehicle up there (cruiseThrustCommand), m = 4 x 0.12 u / 65535 / g;
/// - otherwise (a helix, a trefoil, a ramp: the height never stays), the vertical force balance
///   over the whole airborne flight: the median over the rows at least 0.1 m above the resting
///   height of the motors' thrust (each motor's PWM times the logged battery voltage through the
///   thrust-voltage curve, what the firmware's compensation assumes the motors get) times the
///   cosine of roll and pitch, over g plus the vertical acceleration (the logged vz differentiated
///   over 0.2 s). It needs vz and the motors, and 100 such rows.
/// ssx::Error naming `label` when neither is possible (say --mass KG).
/// `method`: "auto" (as above), "cruise" or "balance" (only that one; an error if it cannot).
MassEstimate identifyMass(const Log& log, const Segment& flight, const std::string& label,
                          const std::string& method = "auto");

/// How unevenly the real vehicle's motors carried it, as rotor thrust factors for a symmetric
/// model: each motor's mean thrust over the airborne rows (0.1 m above the resting height, no motor
/// at full PWM), from its PWM and the logged voltage through the propellers' curve, as a share s_i
/// of the four's mean; the factor is 1 / s_i. A rotor that gives 1 / s_i of the model's thrust
/// needs s_i times the mean command to carry its quarter, as the real one did (whether its
/// propeller was weaker or the centre of mass sat off its centre). ssx::Error naming `label` without
/// the motors or 100 such rows.
std::array<double, 4> rotorThrustFactors(const Log& log, const Segment& flight, const std::string& label);

/// The median of values[first, last).
double median(const std::vector<double>& values, std::size_t first, std::size_t last);

}  // namespace ssx::flight
