#!/usr/bin/python3
"""What the real Crazyflie's controller saw: its onboard estimator (the EKF fed with Vicon's position)
against Vicon, and the firmware's velocity law checked on the logged values, per NanoBench flight.

    estimator.py PROGRAM DATA_DIR OUT_DIR [--write DOC | --check DOC]

PROGRAM is ssx_flight_replay: each flight is flown again (into OUT_DIR) for the columns that compare
the simulated vehicle, whose controller sees the true state (no estimator).

Over each flight's path (score_flight.py's segment, the window its lag is measured on):
- lag: the real flight's lag (score_flight.py);
- velocity at its limit: the share of rows in which the position loop asks for a velocity beyond the
  firmware's 1.1 m/s on x or y (2 x the EKF's position error from the logged set-point), so that the
  velocity asked for is clamped, real / simulated (the simulated one from its true position);
- speed at the limit: the mean speed along an axis while that axis's velocity is clamped, real
  (Vicon's) / simulated;
- EKF velocity / Vicon's: the least-squares gain of the EKF's horizontal velocity on Vicon's (x and y
  together, with an offset, at the time shift within +-0.1 s that fits best);
- Vicon tilt / EKF's: the same for roll and pitch (Vicon's attitude against the EKF's);
- velocity law: the logged attitude command (controller.roll/pitch) against the velocity error the
  firmware computes from the logged set-point and EKF state (clamp(2 (set-point - position), 1.1) -
  velocity): its gain in degrees per m/s (the firmware's velocity loop: 25, plus a small integral)
  and r^2, at the best shift (rows of 10 ms);
then the correlation over the flights of the lag with the other columns. --write puts the table
into DOC between <!-- nanobench-estimator --> and <!-- /nanobench-estimator -->; --check fails
unless DOC's is the one computed now."""
import argparse
import pathlib
import sys

import numpy as np

here = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(here))
import compare  # noqa: E402
import score_flight  # noqa: E402

VELOCITY_MAX = 1.1  # m/s: the firmware's xyVelMax (1.0) x velMaxOverhead (1.1)
POSITION_KP = 2.0  # the position loop's gain (1/s)
SHIFTS = range(-10, 11)  # rows of 10 ms


def read(path):
    with open(path) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return {n: data[:, i] for i, n in enumerate(names)}


def gain(x, y, shifts=SHIFTS):
    """y = k x + b at the shift of y against x (rows) that fits best: (k, r^2, shift)."""
    best = None
    for s in shifts:
        xs, ys = (x[:len(x) - s], y[s:]) if s >= 0 else (x[-s:], y[:s])
        a = np.vstack([xs, np.ones(len(xs))]).T
        coef, res, _, _ = np.linalg.lstsq(a, ys, rcond=None)
        r2 = 1 - res[0] / np.sum((ys - ys.mean()) ** 2)
        if best is None or r2 > best[1]:
            best = (coef[0], r2, s)
    return best


def stacked_gain(pairs):
    """One gain over several (x, y) pairs, each shifted alike."""
    best = None
    for s in SHIFTS:
        k, r2, _ = gain(np.concatenate([x[:len(x) - s] if s >= 0 else x[-s:] for x, _ in pairs]),
                        np.concatenate([y[s:] if s >= 0 else y[:s] for _, y in pairs]), [0])
        if best is None or r2 > best[1]:
            best = (k, r2, s)
    return best


def at_limit(c, position, velocity):
    """The share of rows with a clamped velocity on x or y, and the mean speed along a clamped axis."""
    asked = {a: POSITION_KP * (c[f"sp_{a}"] - c[f"{position}{a}"]) for a in "xy"}
    clamped = {a: np.abs(asked[a]) > VELOCITY_MAX for a in "xy"}
    speeds = np.concatenate([np.abs(c[f"{velocity}{a}"][clamped[a]]) for a in "xy"])
    return float(np.mean(clamped["x"] | clamped["y"])), float(speeds.mean()) if len(speeds) else float("nan"), asked


def window(d, path):
    sc = score_flight.score(str(path))
    t = d["t"]
    w = (t >= t[0] + sc["seg_t0"]) & (t <= t[0] + sc["seg_t1"]) & (d["pz"] > 0.3)
    return {k: v[w] for k, v in d.items()}, sc


def flight(path, sim_path):
    c, sc = window(read(path), path)
    row = {"name": path.stem, "lag": sc["lag_s"], "rows": len(c["t"])}
    if row["rows"] < 300:  # the ramp: the vehicle never rose to its path
        return row
    row["clamped"], row["speed"], asked = at_limit(c, "est_", "v")
    s, sim_score = window(read(sim_path), sim_path)
    row["sim_lag"] = sim_score["lag_s"]
    row["sim_clamped"], row["sim_speed"], _ = at_limit(s, "p", "v")
    row["velocity"] = stacked_gain([(c["vx"], c["est_vx"]), (c["vy"], c["est_vy"])])[0]
    row["tilt"] = stacked_gain([(c["est_roll_deg"], np.degrees(c["roll"])),
                                (-c["est_pitch_deg"], np.degrees(c["pitch"]))])[0]
    if np.any(c["desired_roll_deg"] != 0):  # (trefoil medium: the controller's log group failed)
        error = {a: np.clip(asked[a], -VELOCITY_MAX, VELOCITY_MAX) - c[f"est_v{a}"] for a in "xy"}
        k, r2, shift = stacked_gain([(error["x"], -c["desired_pitch_deg"]), (error["y"], -c["desired_roll_deg"])])
        row["law"] = (k, r2, shift)
    return row


def table(rows):
    out = ["| flight | lag (s) | velocity at its limit | speed at the limit (m/s) | EKF velocity / Vicon's "
           "| Vicon tilt / EKF's | velocity law: deg per m/s (firmware 25), r^2, shift |",
           "|---|---|---|---|---|---|---|"]
    for r in rows:
        if "clamped" not in r:
            out.append(f"| {r['name']} | {r['lag']:.2f} | never flew its path | | | | |")
            continue
        law = "log group failed"
        if "law" in r:
            k, r2, shift = r["law"]
            law = f"{k:.1f}, {r2:.3f}, {shift * 10:+d} ms"
        speed = "-" if np.isnan(r["speed"]) else f"{r['speed']:.2f} / {r['sim_speed']:.2f}".replace("nan", "-")
        out.append(f"| {r['name']} | {r['lag']:.2f} / {r['sim_lag']:.2f} | {100 * r['clamped']:.1f} / "
                   f"{100 * r['sim_clamped']:.1f} % | {speed} | {r['velocity']:.3f} | "
                   f"{r['tilt']:.3f} | {law} |")
    flown = [r for r in rows if "clamped" in r]
    lag = np.array([r["lag"] for r in flown])
    out.append("")
    for key, what in (("clamped", "the share of time at the velocity limit"),
                      ("velocity", "the EKF's velocity gain"), ("tilt", "the tilt gain")):
        rho = np.corrcoef(lag, [r[key] for r in flown])[0, 1]
        out.append(f"- correlation over the {len(flown)} flights of the lag with {what}: {rho:+.2f}")
    slow = [r["velocity"] for r in flown if r["lag"] < 0.5]
    long_ = [r["velocity"] for r in flown if r["lag"] >= 0.57]
    out.append(f"- EKF velocity / Vicon's: {min(slow):.3f}-{max(slow):.3f} on the {len(slow)} flights that lag under "
               f"0.5 s, {min(long_):.3f}-{max(long_):.3f} on the {len(long_)} that lag 0.57 s or more")
    return "\n".join(out)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("program")
    p.add_argument("data", type=pathlib.Path)
    p.add_argument("out", type=pathlib.Path)
    g = p.add_mutually_exclusive_group()
    g.add_argument("--write", type=pathlib.Path)
    g.add_argument("--check", type=pathlib.Path)
    a = p.parse_args()
    flights = sorted(a.data.glob("B*_rep*.csv"), key=compare.flight_order)
    if len(flights) != 22:
        sys.exit(f"{a.data}: expected the 22 NanoBench flights, found {len(flights)}")
    a.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for f in flights:
        compare.replay(a.program, f, a.out / f.name, [])
        rows.append(flight(f, a.out / f.name))
    text = table(rows)
    print(text)
    doc = a.write or a.check
    return compare.put(doc, "nanobench-estimator", text, a.write is not None) if doc else 0


if __name__ == "__main__":
    sys.exit(main())
