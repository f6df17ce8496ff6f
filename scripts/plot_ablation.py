#!/usr/bin/python3
"""Draws the fidelity ablation: the figure-eight tracking error (mean with its standard deviation)
of every configuration `ssx_fidelity_eight --ablation` prints, horizontal and vertical, against the
paper's real flight. Needs Debian's python3-matplotlib.

usage: build/bin/ssx_fidelity_eight --ablation > ablation.txt
       /usr/bin/python3 scripts/plot_ablation.py ablation.txt docs/fidelity_ablation.png
"""
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

REAL = {"horizontal": (0.0919, 0.0412), "vertical": (0.0654, 0.0179)}  # SwarmSimX paper, Fig. 4


def main():
    source, out = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "fidelity_ablation.png"
    rows = []
    for line in open(source):
        m = re.match(r"config=(\S+) horizontal_mean_m=(\S+) horizontal_std_m=(\S+) "
                     r"vertical_mean_m=(\S+) vertical_std_m=(\S+)", line)
        if m:
            rows.append((m.group(1), *map(float, m.groups()[1:])))
    if not rows:
        sys.exit(f"{source}: no config= lines")
    fig, ax = plt.subplots(figsize=(10, 4.8))
    y = range(len(rows))
    ax.errorbar([r[1] for r in rows], [i - 0.15 for i in y], xerr=[r[2] for r in rows], fmt="o", capsize=3,
                label="horizontal eight")
    ax.errorbar([r[3] for r in rows], [i + 0.15 for i in y], xerr=[r[4] for r in rows], fmt="s", capsize=3,
                label="vertical eight")
    for kind, style in (("horizontal", "-"), ("vertical", "--")):
        ax.axvline(REAL[kind][0], color="gray", ls=style, lw=1, label=f"paper, real flight, {kind}")
    ax.set_yticks(list(y))
    ax.set_yticklabels([r[0] for r in rows])
    ax.invert_yaxis()
    ax.set_xlabel("tracking error, mean +- std (m), last 3 of 4 periods")
    ax.set_title("ssx_fidelity_eight --ablation: each effect alone, and all of the realistic profile")
    ax.legend(loc="center right", fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
