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


def takeoff_window(path):
    """From the first set-point that is not all zeros to the start of the figure eight."""
    c = score_flight.read_csv(str(path))
    g = score_flight.resample(c)
    flying = np.nonzero((g["sp_x"] != 0) | (g["sp_y"] != 0) | (g["sp_z"] != 0))[0]
    i0, _, cruise = score_flight.active_segment(g, 0.1, 0.0)
    h = int(round(score_flight.HALF_WIN / score_flight.GRID_DT))
    return float(g["t"][flying[0]]), float(g["t"][i0 - h]), cruise


def replay(program, log, out, extra):
    run = subprocess.run([program, str(log), "--out", str(out), *extra], capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"{program} {log}: {run.stderr.strip()}")
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
                     "real": {**real, **dict(zip(("rise_s", "overshoot_m"), takeoff(log, window)))},
                     "sim": {**simulated, **dict(zip(("rise_s", "overshoot_m"), takeoff(sim, window)))}})
    return rows


def targets(r):
    real, sim = r["real"], r["sim"]
    return {
        "mean within 15 %": abs(sim["mean_m"] - real["mean_m"]) <= 0.15 * real["mean_m"],
        "lag within 0.05 s": abs(sim["lag_s"] - real["lag_s"]) <= 0.05 + 1e-9,
        "after the lag within 50 %": abs(sim["mean_after_lag_m"] - real["mean_after_lag_m"]) <= 0.5 * real["mean_after_lag_m"],
        "overshoot within 30 %": abs(sim["overshoot_m"] - real["overshoot_m"]) <= 0.3 * abs(real["overshoot_m"]),
    }


def table(rows):
    lines = ["| flight | mass (g) | mean (m) | lag (s) | after the lag (m) | max (m) | take-off rise (s) | overshoot (m) | targets missed |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        real, sim = r["real"], r["sim"]
        missed = [name for name, ok in targets(r).items() if not ok]
        lines.append(f"| {r['flight']} | {r['mass_g']:.1f} | {real['mean_m']:.3f} / {sim['mean_m']:.3f} | "
                     f"{real['lag_s']:.2f} / {sim['lag_s']:.2f} | {real['mean_after_lag_m']:.3f} / {sim['mean_after_lag_m']:.3f} | "
                     f"{real['max_m']:.3f} / {sim['max_m']:.3f} | {real['rise_s']:.2f} / {sim['rise_s']:.2f} | "
                     f"{real['overshoot_m']:.3f} / {sim['overshoot_m']:.3f} | {', '.join(missed) if missed else 'none'} |")
    return "\n".join(lines)


def plots(rows, data, out_dir, plot_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    for speed in ("slow", "fast"):
        name = next(r["flight"] for r in rows if f"_{speed}_" in r["flight"])
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
    g = p.add_mutually_exclusive_group()
    g.add_argument("--write", type=pathlib.Path)
    g.add_argument("--check", type=pathlib.Path)
    a = p.parse_args(argv)
    flights = sorted(a.data.glob("B3_*.csv"))
    if len(flights) != 5:
        sys.exit(f"{a.data}: expected the five NanoBench flights, found {len(flights)}")
    a.out.mkdir(parents=True, exist_ok=True)
    if a.sweep:
        text, marker = sweep(a.program, flights, a.out, extra), "nanobench-sweep"
    else:
        rows = compare(a.program, flights, a.out, extra)
        text, marker = table(rows), "nanobench-table"
        if a.plots:
            plots(rows, a.data, a.out, a.plots)
    print(text)
    doc = a.write or a.check
    return put(doc, marker, text, a.write is not None) if doc else 0


if __name__ == "__main__":
    sys.exit(main())
