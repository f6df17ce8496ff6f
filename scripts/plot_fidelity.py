#!/usr/bin/python3
"""Draws the cumulative tracking error F(d) of the figure-eight fidelity study (paper Fig. 4).

Reads eight_horizontal.csv and eight_vertical.csv written by ssx_fidelity_eight, scores the
same samples it does (the last 3 of 4 periods, t >= 12 s), and draws F(d), the fraction of
samples with ||p_d - p|| < d, for both trajectories, with our mean and the paper's real-flight
and simulated means marked. Needs Debian's python3-matplotlib.

usage: /usr/bin/python3 scripts/plot_fidelity.py [CSV_DIR] [OUTPUT.png]
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PAPER = {  # mean, std in m (SwarmSimX paper, Fig. 4)
    "eight_horizontal": {"real": (0.0919, 0.0412), "simulated": (0.1245, 0.0444)},
    "eight_vertical": {"real": (0.0654, 0.0179), "simulated": (0.0546, 0.0131)},
}
SCORED_FROM_S = 12.0


def errors(path):
    with open(path, newline="") as f:
        return sorted(float(r["error_m"]) for r in csv.DictReader(f) if float(r["t_s"]) >= SCORED_FROM_S)


def main():
    csv_dir = sys.argv[1] if len(sys.argv) > 1 else "."
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(csv_dir, "fidelity_eight.png")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for ax, kind in zip(axes, ("eight_horizontal", "eight_vertical")):
        e = errors(os.path.join(csv_dir, kind + ".csv"))
        n = len(e)
        mean = sum(e) / n
        std = (sum((x - mean) ** 2 for x in e) / (n - 1)) ** 0.5
        ax.step(e, [(i + 1) / n for i in range(n)], where="post", color="tab:blue",
                label=f"ssx: mean {mean:.4f} m, std {std:.4f} m")
        ax.axvline(mean, color="tab:blue", linestyle=":")
        for source, color in (("real", "tab:red"), ("simulated", "tab:gray")):
            m, s = PAPER[kind][source]
            ax.axvline(m, color=color, linestyle="--", label=f"paper, {source}: mean {m:.4f} m, std {s:.4f} m")
        ax.set_title(kind.replace("_", " ") + f" ({n} samples at 50 Hz)")
        ax.set_xlabel("d (m)")
        ax.set_xlim(0, max(0.25, e[-1] * 1.05))
        ax.grid(alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
    axes[0].set_ylabel("F(d): fraction of time closer than d")
    fig.suptitle("Figure-eight tracking error, last 3 of 4 periods (cf. SwarmSimX Fig. 4)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
