#!/usr/bin/python3
"""Makes the trimmed copy of the NanoBench flights kept in data/ from the dataset's own
files (https://github.com/syediu/nanobench-iros2026, commit 0ae7d689, datasets/dataset/): the
columns the Crazyflie check uses, time from the file's first row, and fewer digits than the
source's nanometres (positions to 0.1 mm, voltages to 1 mV, angles to 0.01 degree). The
scores of the trimmed files are those of the source files (data/README.md; tested).

    trim.py SOURCE_DIR OUT_DIR"""
import csv
import pathlib
import sys

FLIGHTS = [
    "B10_lissajous_slow_rep1",
    "B2_circle_fast_rep1",
    "B2_circle_medium_rep1",
    "B2_circle_slow_rep1",
    "B3_figure8_fast_rep1",
    "B3_figure8_fast_rep2",
    "B3_figure8_slow_rep1",
    "B3_figure8_slow_rep2",
    "B3_figure8_slow_rep3",
    "B5_helix_fast_rep1",
    "B5_helix_medium_rep1",
    "B5_helix_slow_rep1",
    "B6_linear_ramp_rep1",
    "B7_oval_fast_rep1",
    "B7_oval_medium_rep1",
    "B7_oval_slow_rep2",
    "B8_star_fast_rep1",
    "B8_star_medium_rep1",
    "B8_star_slow_rep1",
    "B9_trefoil_fast_rep1",
    "B9_trefoil_medium_rep1",
    "B9_trefoil_slow_rep1",
]
# (column in the source, column here, digits after the point)
COLUMNS = [("px", "px", 4), ("py", "py", 4), ("pz", "pz", 4),
           ("vx", "vx", 3), ("vy", "vy", 3), ("vz", "vz", 3),
           ("roll", "roll", 4), ("pitch", "pitch", 4), ("yaw", "yaw", 4),
           ("sp_ctrltarget_x", "sp_x", 4), ("sp_ctrltarget_y", "sp_y", 4), ("sp_ctrltarget_z", "sp_z", 4),
           ("sp_ctrltarget_yaw", "sp_yaw_rate_dps", 2),
           ("pid_controller_roll", "desired_roll_deg", 2), ("pid_controller_pitch", "desired_pitch_deg", 2),
           ("pid_controller_cmd_thrust", "cmd_thrust", 0),
           ("motor_motor_m1", "m1", 0), ("motor_motor_m2", "m2", 0), ("motor_motor_m3", "m3", 0),
           ("motor_motor_m4", "m4", 0), ("pwr_pm_vbat", "vbat", 3),
           # the onboard estimator (the EKF fed with Vicon's position): what the controller saw
           ("est_stateEstimate_x", "est_x", 4), ("est_stateEstimate_y", "est_y", 4),
           ("est_stateEstimate_vx", "est_vx", 3), ("est_stateEstimate_vy", "est_vy", 3),
           ("att_stateEstimate_roll", "est_roll_deg", 2), ("att_stateEstimate_pitch", "est_pitch_deg", 2),
           # what the estimator was fed besides Vicon: the IMU (specific force in g, rates in rad/s)
           ("imu_acc_x", "acc_x_g", 4), ("imu_acc_y", "acc_y_g", 4), ("imu_acc_z", "acc_z_g", 4),
           ("imu_gyro_x", "gyro_x", 4), ("imu_gyro_y", "gyro_y", 4), ("imu_gyro_z", "gyro_z", 4)]


def main():
    source, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    for name in FLIGHTS:
        with open(source / f"{name}.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        t0 = float(rows[0]["t"])
        with open(out / f"{name}.csv", "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(["t"] + [c[1] for c in COLUMNS])
            for r in rows:
                values = [f"{float(r['t']) - t0:.3f}"]
                for src, _, digits in COLUMNS:
                    v = float(r[src])
                    values.append(f"{v:.{digits}f}" if digits > 0 else str(int(round(v))))
                w.writerow(values)
        print(f"{name}: {len(rows)} rows")


if __name__ == "__main__":
    main()
