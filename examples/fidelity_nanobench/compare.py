#!/usr/bin/python3
"""Flies each NanoBench flight again with ssx_flight_replay and compares it with the real one.

    compare.py PROGRAM DATA_DIR OUT_DIR [--plots DIR] [--write DOC | --check DOC] [--sweep]
               [-- REPLAY_OPTIONS...]

For every B3_*.csv of DATA_DIR: the simulated flight goes to OUT_DIR; both are scored by
score_flight.py (mean distance to the set-point over the figure eight, the lag, the distance after
the lag, the max) and by their take-off (the climb from the first set-point to the start of the
eight: the rise time to 90 % of the climb, the overshoot above the cruise set-point). Prints a
Markdown table, real / simulated, and the issue's targets per flight: the simulated mean within 15 %
of the real one, the lag within 0.05 s, the distance after the lag within 50 %, the take-off
overshoot within 30 %.

--plots DIR   writes nanobench_slow.png and nanobench_fast.png (x(t) and y(t), real and simulated,
              of each speed's first flight)
--write DOC   puts the table into DOC between <!-- nanobench-table --> and <!-- /nanobench-table -->
              (with --sweep: <!-- nanobench-sweep --> ...)
--check DOC   fails (exit 1) unless DOC's table is the one computed now
--sweep       flies every flight once per value of each unpublished parameter and prints how much
              the mean, the lag, the distance after the lag and the take-off overshoot move (the
              mean over the five flights)
Anything after -- goes to ssx_flight_replay (e.g. -- --physics bullet)."""
import argparse
import pathlib
import re
import subprocess
import sys
import time

import numpy as np

here = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(here))
import score_flight  # noqa: E402


# the values nobody published for this vehicle and their plausible ranges (each flown alone)
SWEEP = [
    ("motor time constant (published 60-72 ms)", "--driver", ["time_constant_up={0}", "time_constant_down={0}"],
     ["0.055", "0.065", "0.075"]),
    ("motion capture to controller latency (none published for NanoBench)", "--sensor", ["delay={0}"],
     ["0", "0.01", "0.02", "0.03"]),
    ("inertia of the heavier vehicle (Förster's for 27 g; the payload's is unknown)", "--inertia-scale", None,
     ["1.0", "1.2", "1.4"]),
    ("rotor drag (Förster's 9.18e-7; RotorPy 1.03e-6; none)", "--driver", ["rotor_drag_coefficient={0}"],
     ["0", "9.1785e-7", "1.2e-6"]),
    ("take-off mass, kg (identified per flight: 43.0-45.7 g)", "--mass", None, ["0.040", "0.045"]),
]


SPEEDS = {"slow": 0, "medium": 1, "fast": 2}


def flight_order(path):
    """B2 before B10; in a family slow, medium, fast, then the repetition."""
    m = re.match(r"B(\d+)_(.*?)(?:_(slow|medium|fast))?_rep(\d+)$", path.stem)
    return (int(m.group(1)), SPEEDS.get(m.group(3), -1), int(m.group(4))) if m else (99, 0, 0)


def takeoff(path, window):
    """Rise time (s) to 90 % of the climb and overshoot (m) above the cruise set-point, over the
    real flight's take-off window (t0, t1, cruise)."""
    c = score_flight.read_csv(str(path))
    t0, t1, cruise = window
    sel = (c["t"] >= t0) & (c["t"] <= t1)
    t, z = c["t"][sel], c["pz"][sel]
    z0 = z[0]
    above = np.nonzero(z >= z0 + 0.9 * (cruise - z0))[0]
    rise = float(t[above[0]] - t0) if len(above) else float("nan")
    return rise, float(z.max() - cruise)


def horizontal_drag(path):
    """The horizontal drag per unit mass and speed (1/s) the flight shows, from its own force balance
    (nothing of the tracking error): the thrust's horizontal part per unit mass, (g + a_z) / z_b.z
    times z_b's horizontal part (z_b the body's up axis from roll, pitch and yaw), less the
    horizontal acceleration (the logged velocity differentiated over 0.2 s), fitted by least squares
    as bias - c v (a bias per axis takes up the markers' tilt on the body), over the rows above
    0.5 m moving faster than 0.05 m/s; c is returned."""
    names = ("t", "vx", "vy", "vz", "roll", "pitch", "yaw", "pz")
    d = np.genfromtxt(path, delimiter=",", names=True, usecols=names)
    t, r, p, y = d["t"], d["roll"], d["pitch"], d["yaw"]
    zb = np.stack([np.cos(y) * np.sin(p) * np.cos(r) + np.sin(y) * np.sin(r),
                   np.sin(y) * np.sin(p) * np.cos(r) - np.cos(y) * np.sin(r), np.cos(p) * np.cos(r)], 1)
    v = np.stack([d["vx"], d["vy"], d["vz"]], 1)
    k = 10
    a = np.zeros_like(v)
    a[k:-k] = (v[2 * k:] - v[:-2 * k]) / (t[2 * k:] - t[:-2 * k])[:, None]
    res = ((9.81 + a[:, 2]) / zb[:, 2])[:, None] * zb[:, :2] - a[:, :2]
    sel = (d["pz"] > 0.5) & (np.hypot(v[:, 0], v[:, 1]) > 0.05)
    sel[:5 * k] = False
    sel[-5 * k:] = False
    n = int(sel.sum())
    if n < 100:
        return float("nan")
    one, zero = np.ones(n), np.zeros(n)
    x = np.concatenate([np.stack([one, zero, -v[sel, 0]], 1), np.stack([zero, one, -v[sel, 1]], 1)])
    fit = np.linalg.lstsq(x, np.concatenate([res[sel, 0], res[sel, 1]]), rcond=None)[0]
    return float(-fit[2])


def takeoff_window(path):
    """From the first set-point that is not all zeros to the start of the figure eight."""
    c = score_flight.read_csv(str(path))
    g = score_flight.resample(c)
    flying = np.nonzero((g["sp_x"] != 0) | (g["sp_y"] != 0) | (g["sp_z"] != 0))[0]
    i0, _, cruise = score_flight.active_segment(g, 0.1, 0.0)
    h = int(round(score_flight.HALF_WIN / score_flight.GRID_DT))
    return float(g["t"][flying[0]]), float(g["t"][i0 - h]), cruise


REPLAYED = {"flights": 0, "flight_s": 0.0, "wall_s": 0.0, "longest": (0.0, 0.0)}  # what the replays took


def replay(program, log, out, extra):
    started = time.perf_counter()
    run = subprocess.run([program, str(log), "--out", str(out), *extra], capture_output=True, text=True)
    wall = time.perf_counter() - started
    if run.returncode != 0:
        sys.exit(f"{program} {log}: {run.stderr.strip()}")
    span = re.search(r"flight ([\d.]+)-([\d.]+) s", run.stdout)
    if span:
        flight = float(span.group(2)) - float(span.group(1))
        REPLAYED["flights"] += 1
        REPLAYED["flight_s"] += flight
        REPLAYED["wall_s"] += wall
        REPLAYED["longest"] = max(REPLAYED["longest"], (flight, wall))
    return run.stdout


def compare(program, flights, out_dir, extra):
    rows = []
    for log in flights:
        sim = out_dir / log.name
        printed = replay(program, log, sim, extra)
        mass = re.search(r"take-off mass ([\d.]+) g", printed)
        real, simulated = score_flight.score(str(log)), score_flight.score(str(sim))
        window = takeoff_window(log)
        rows.append({"flight": log.stem, "mass_g": float(mass.group(1)) if mass else float("nan"),
                     "real": {**real, **dict(zip(("rise_s", "overshoot_m"), takeoff(log, window))),
                              "drag": horizontal_drag(log)},
                     "sim": {**simulated, **dict(zip(("rise_s", "overshoot_m"), takeoff(sim, window))),
                             "drag": horizontal_drag(sim)}})
    return rows


def targets(r):
    real, sim = r["real"], r["sim"]
    return {
        "mean within 15 %": abs(sim["mean_m"] - real["mean_m"]) <= 0.15 * real["mean_m"],
        "lag within 0.05 s": abs(sim["lag_s"] - real["lag_s"]) <= 0.05 + 1e-9,
        "after the lag within 50 %": abs(sim["mean_after_lag_m"] - real["mean_after_lag_m"]) <= 0.5 * real["mean_after_lag_m"],
        "overshoot within 30 %": abs(sim["overshoot_m"] - real["overshoot_m"]) <= 0.3 * abs(real["overshoot_m"]),
    }


# the targets: how many of the 22 flights each must be met on
REQUIRED = {"mean within 15 %": 20, "lag within 0.05 s": 20, "after the lag within 50 %": 20, "overshoot within 30 %": 18}


def met_counts(rows):
    """'target: met on N of M (required R)' for each target."""
    out = []
    for name, required in REQUIRED.items():
        n = sum(targets(r)[name] for r in rows)
        verdict = "met" if n >= required * len(rows) / 22 else "NOT met"
        out.append(f"{name}: {n} of {len(rows)} (asked: {required} of 22; {verdict})")
    return out


def table(rows):
    lines = ["| flight | mass (g) | mean (m) | lag (s) | after the lag (m) | max (m) | take-off rise (s) | overshoot (m) | drag (1/s) | targets missed |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        real, sim = r["real"], r["sim"]
        missed = [name for name, ok in targets(r).items() if not ok]
        lines.append(f"| {r['flight']} | {r['mass_g']:.1f} | {real['mean_m']:.3f} / {sim['mean_m']:.3f} | "
                     f"{real['lag_s']:.2f} / {sim['lag_s']:.2f} | {real['mean_after_lag_m']:.3f} / {sim['mean_after_lag_m']:.3f} | "
                     f"{real['max_m']:.3f} / {sim['max_m']:.3f} | {real['rise_s']:.2f} / {sim['rise_s']:.2f} | "
                     f"{real['overshoot_m']:.3f} / {sim['overshoot_m']:.3f} | {real['drag']:.2f} / {sim['drag']:.2f} | "
                     f"{', '.join(missed) if missed else 'none'} |")
    lines.append("")
    lines += [f"- {line}" for line in met_counts(rows)]
    return "\n".join(lines)


# candidate effects, each flown alone over the 22 flights (`--ablation`): what it is, replay options
ABLATION = [
    ("as published (the preset)", []),
    ("rotor drag 2.0e-6 N s/m per rad/s (identified from the flights' force balance, below)",
     ["--driver", "rotor_drag_coefficient=2.0e-6"]),
    ("no rotor drag", ["--driver", "rotor_drag_coefficient=0"]),
    ("motion capture to controller latency 0.02 s", ["--sensor", "delay=0.02"]),
    ("the logged battery voltage row by row (its sag under load and over the flight)", ["--battery", "log"]),
    ("each rotor's thrust factor from the motors' shares in the log", ["--rotor-factors", "log"]),
    ("the firmware's Kalman filter between the IMU and motion capture and the loops (crazyflie_estimator)",
     ["--driver", "crazyflie_estimator=kalman"]),
    ("the Kalman filter and the rotor drag of 2.0e-6 together", ["--driver", "crazyflie_estimator=kalman",
                                                                 "--driver", "rotor_drag_coefficient=2.0e-6"]),
]


def motors_saturated(path):
    """(share of the airborne rows (above 0.3 m) with a motor at full PWM, the battery's 5th and
    95th percentile there), from a real log."""
    d = np.genfromtxt(path, delimiter=",", names=True, usecols=("pz", "m1", "m2", "m3", "m4", "vbat"))
    air = d["pz"] > 0.3
    if not air.any():
        return float("nan"), float("nan"), float("nan")
    top = np.max(np.stack([d[m][air] for m in ("m1", "m2", "m3", "m4")], 1), axis=1)
    return float(np.mean(top >= 65000)), *np.percentile(d["vbat"][air], [5, 95])


def ablation(program, flights, out_dir, extra):
    lines = ["| effect | mean within 15 % | lag within 0.05 s | after the lag within 50 % | overshoot within 30 % | simulated lag (s) | simulated drag (1/s) |",
             "|---|---|---|---|---|---|---|"]
    for label, args in ABLATION:
        rows = compare(program, flights, out_dir, [*extra, *args])
        counts = [sum(targets(r)[name] for r in rows) for name in REQUIRED]
        lags = [r["sim"]["lag_s"] for r in rows]
        drag = round(float(np.median([r["sim"]["drag"] for r in rows])), 2) or 0.0  # -0.0 is falsy: no "-0.00"
        lines.append(f"| {label} | " + " | ".join(f"{n} of {len(rows)}" for n in counts) +
                     f" | {min(lags):.2f}-{max(lags):.2f} | {drag:.2f} |")
        if not args:
            published = rows
    # the real flights that lag most, and their motors and batteries
    lines += ["", "| flight (the eight real flights that lag most) | real lag (s) | simulated lag (s) | real motors at full PWM | real battery in flight (V, 5-95 %) |",
              "|---|---|---|---|---|"]
    data = flights[0].parent
    for r in sorted(published, key=lambda r: -r["real"]["lag_s"])[:8]:
        share, low, high = motors_saturated(data / f"{r['flight']}.csv")
        lines.append(f"| {r['flight']} | {r['real']['lag_s']:.2f} | {r['sim']['lag_s']:.2f} | {100 * share:.1f} % | {low:.2f}-{high:.2f} |")
    return "\n".join(lines)


def family_plot(rows, data, out_dir, plot_dir):
    """nanobench_families.png: each family's fastest flight seen from above (real and simulated)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    chosen = {}
    for r in rows:  # rows are in family order, slow to fast: the last of a family is its fastest
        chosen[r["flight"].split("_")[0]] = r["flight"]
    fig, axes = plt.subplots(2, 4, figsize=(13, 6.8))
    for ax, name in zip(axes.flat, chosen.values()):
        real = score_flight.read_csv(str(data / f"{name}.csv"))
        sim = score_flight.read_csv(str(out_dir / f"{name}.csv"))
        up = real["pz"] > 0.3
        ax.plot(real["sp_x"][up], real["sp_y"][up], color="0.6", lw=1, ls="--", label="set-point")
        ax.plot(real["px"][up], real["py"][up], color="tab:blue", lw=1.1, label="real (Vicon)")
        ax.plot(sim["px"][sim["pz"] > 0.3], sim["py"][sim["pz"] > 0.3], color="tab:orange", lw=1.1, label="ssx")
        ax.set_title(name, fontsize=9)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(chosen):]:
        ax.axis("off")
    axes.flat[0].legend(loc="lower left", fontsize=7)
    fig.suptitle("Every family's fastest flight from above (x, y in m; above 0.3 m): real and simulated")
    fig.tight_layout()
    fig.savefig(plot_dir / "nanobench_families.png", dpi=80)
    plt.close(fig)


def plots(rows, data, out_dir, plot_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    family_plot(rows, data, out_dir, plot_dir)
    for speed in ("slow", "fast"):
        name = next(r["flight"] for r in rows if r["flight"].startswith(f"B3_figure8_{speed}_"))
        real = score_flight.read_csv(str(data / f"{name}.csv"))
        sim = score_flight.read_csv(str(out_dir / f"{name}.csv"))
        fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
        for ax, k in zip(axes, ("x", "y")):
            ax.plot(real["t"], real[f"sp_{k}"], color="0.6", lw=1, ls="--", label="set-point")
            ax.plot(real["t"], real[f"p{k}"], color="tab:blue", lw=1.3, label="real (Vicon)")
            ax.plot(sim["t"], sim[f"p{k}"], color="tab:orange", lw=1.3, label="ssx")
            ax.set_ylabel(f"{k} (m)")
            ax.grid(alpha=0.3)
        axes[0].legend(loc="lower left", ncol=3, fontsize=8)
        axes[1].set_xlabel("time (s)")
        fig.suptitle(f"{name}: the Crazyflie's firmware controller, real and simulated")
        fig.tight_layout()
        fig.savefig(plot_dir / f"nanobench_{speed}.png", dpi=90)
        plt.close(fig)


def sweep(program, flights, out_dir, extra):
    lines = ["| unpublished value | flown | mean (m) | lag (s) | after the lag (m) | take-off overshoot (m) |",
             "|---|---|---|---|---|---|"]
    for label, option, forms, values in SWEEP:
        for v in values:
            args = [option, v] if forms is None else [a for f in forms for a in (option, f.format(v))]
            rows = compare(program, flights, out_dir, [*extra, *args])
            m = [np.mean([r["sim"][k] for r in rows]) for k in ("mean_m", "lag_s", "mean_after_lag_m", "overshoot_m")]
            lines.append(f"| {label} | {v} | {m[0]:.3f} | {m[1]:.2f} | {m[2]:.3f} | {m[3]:.3f} |")
    return "\n".join(lines)


def put(doc_path, marker, text, write):
    """Writes `text` between <!-- marker --> and <!-- /marker --> of the document, or checks that it
    is there; returns the exit status."""
    begin, end = f"<!-- {marker} -->", f"<!-- /{marker} -->"
    doc = doc_path.read_text()
    if begin not in doc or end not in doc:
        print(f"{doc_path}: no {begin} ... {end}", file=sys.stderr)
        return 1
    head, rest = doc.split(begin, 1)
    old, tail = rest.split(end, 1)
    if write:
        doc_path.write_text(f"{head}{begin}\n{text}\n{end}{tail}")
        return 0
    if old.strip() != text.strip():
        print(f"{doc_path}: its {marker} is not the one computed now (above): run compare.py --write", file=sys.stderr)
        return 1
    print(f"{doc_path}: its {marker} is the one computed now")
    return 0


def main():
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    argv = argv[:argv.index("--")] if "--" in argv else argv
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("program")
    p.add_argument("data", type=pathlib.Path)
    p.add_argument("out", type=pathlib.Path)
    p.add_argument("--plots", type=pathlib.Path)
    p.add_argument("--sweep", action="store_true")
    p.add_argument("--ablation", action="store_true")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--write", type=pathlib.Path)
    g.add_argument("--check", type=pathlib.Path)
    a = p.parse_args(argv)
    flights = sorted(a.data.glob("B*_rep*.csv"), key=flight_order)
    if len(flights) != 22:
        sys.exit(f"{a.data}: expected the 22 NanoBench flights, found {len(flights)}")
    if a.sweep:  # the unpublished values' sweep flies the figure eights (the flights they were read from)
        flights = [f for f in flights if f.name.startswith("B3_")]
    a.out.mkdir(parents=True, exist_ok=True)
    if a.sweep:
        text, marker = sweep(a.program, flights, a.out, extra), "nanobench-sweep"
    elif a.ablation:
        text, marker = ablation(a.program, flights, a.out, extra), "nanobench-ablation"
    else:
        rows = compare(a.program, flights, a.out, extra)
        text, marker = table(rows), "nanobench-table"
        if a.plots:
            plots(rows, a.data, a.out, a.plots)
    print(text)
    if REPLAYED["flights"]:
        longest, wall = REPLAYED["longest"]
        print(f"replayed {REPLAYED['flights']} flights ({REPLAYED['flight_s']:.0f} s of flight) in "
              f"{REPLAYED['wall_s']:.1f} s of wall time, the program's start included: "
              f"{60 * REPLAYED['wall_s'] / REPLAYED['flight_s']:.2f} s per 60 s of flight; the longest "
              f"({longest:.1f} s) in {wall:.2f} s", file=sys.stderr)
    doc = a.write or a.check
    return put(doc, marker, text, a.write is not None) if doc else 0


if __name__ == "__main__":
    sys.exit(main())
