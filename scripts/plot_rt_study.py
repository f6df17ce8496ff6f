#!/usr/bin/python3
"""Draws the real-time study (paper Fig. 5) from the CSV that ssx_rt_study --csv writes.

Left: box plots of the step compute time for each N, with tau marked. Right: the median compute
time per robot against N (log axis), which is flat when the cost is linear in the robots.
Needs Debian's python3-matplotlib.

usage: /usr/bin/python3 scripts/plot_rt_study.py STUDY.csv [OUTPUT.png] [TAU_MS]
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    path = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else path.rsplit(".", 1)[0] + ".png"
    tau_ms = float(sys.argv[3]) if len(sys.argv) > 3 else 20.0
    times = defaultdict(list)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            times[int(row["n"])].append(int(row["total_ns"]) * 1e-6)
    sizes = sorted(times)
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    left.boxplot([times[n] for n in sizes], labels=[str(n) for n in sizes], whis=(1, 99), showfliers=True,
                 flierprops={"markersize": 2})
    left.axhline(tau_ms, color="tab:red", linestyle="--", label=f"tau = {tau_ms:g} ms")
    left.set_yscale("log")
    left.set_xlabel("robots")
    left.set_ylabel("step compute time (ms)")
    left.set_title("compute time per step (whiskers: p1-p99)")
    left.legend()
    per_robot = [sorted(times[n])[len(times[n]) // 2] * 1e3 / n for n in sizes]
    right.plot(sizes, per_robot, "o-")
    right.set_xscale("log")
    right.set_xlabel("robots")
    right.set_ylabel("median compute per robot per step (us)")
    right.set_ylim(bottom=0)
    right.grid(alpha=0.3)
    right.set_title("cost per robot")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
