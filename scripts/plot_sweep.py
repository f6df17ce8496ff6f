#!/usr/bin/env python3
"""Plots one metric of an `ssx sweep` results file over one varied parameter: every run that
finished as a dot, the mean and standard deviation per value as a line with error bars; failed
runs are counted in the title. Other parameters, if any, are pooled.

    python3 scripts/plot_sweep.py formation_gains.csv gain formation_time --out docs/sweep_formation_gains.png
"""
import argparse
import csv
import math
import sys
from collections import defaultdict


def read_rows(path):
    with open(path, newline="") as f:
        lines = [line for line in f if not line.startswith("#")]
    return list(csv.DictReader(lines))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", help="the CSV that ssx sweep --out wrote")
    parser.add_argument("parameter", help="a varied parameter's column (its x axis)")
    parser.add_argument("metric", help="a metric's column (its y axis)")
    parser.add_argument("--out", default=None, help="PNG to write (default: RESULTS_PARAMETER_METRIC.png)")
    parser.add_argument("--log-x", action="store_true", help="logarithmic x axis")
    args = parser.parse_args(argv)

    rows = read_rows(args.results)
    if not rows:
        sys.exit(f"{args.results}: no runs in it")
    for column in (args.parameter, args.metric):
        if column not in rows[0]:
            sys.exit(f"{args.results}: no column '{column}' (it has: {', '.join(rows[0].keys())})")
    values = defaultdict(list)
    failed = defaultdict(int)
    for row in rows:
        x = float(row[args.parameter])
        if row["status"] != "ok":
            failed[x] += 1
        elif row[args.metric] != "":
            values[x].append(float(row[args.metric]))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xs = sorted({float(row[args.parameter]) for row in rows})
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for x in xs:
        ax.plot([x] * len(values[x]), values[x], "o", color="tab:blue", alpha=0.35, ms=4)
    means = [sum(values[x]) / len(values[x]) if values[x] else math.nan for x in xs]
    stds = [
        math.sqrt(sum((v - m) ** 2 for v in values[x]) / (len(values[x]) - 1)) if len(values[x]) > 1 else 0.0
        for x, m in zip(xs, means)
    ]
    ax.errorbar(xs, means, yerr=stds, color="tab:red", capsize=4, lw=1.5, label="mean +- std")
    for x in xs:
        missing = sum(1 for r in rows if float(r[args.parameter]) == x and r["status"] == "ok" and r[args.metric] == "")
        if missing:
            ax.annotate(f"{missing} run(s)\nwithout a value", (x, 0.5), xycoords=("data", "axes fraction"),
                        ha="center", va="center", fontsize=8)
    if args.log_x:
        ax.set_xscale("log")
    total_failed = sum(failed.values())
    ax.set_xlabel(args.parameter)
    ax.set_ylabel(args.metric)
    ax.set_title(f"{args.metric} over {args.parameter}: {len(rows)} runs, {total_failed} failed")
    ax.legend(loc="lower left")
    fig.tight_layout()
    out = args.out or f"{args.results.rsplit('.', 1)[0]}_{args.parameter}_{args.metric}.png"
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
