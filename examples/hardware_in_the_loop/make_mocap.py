#!/usr/bin/env python3
"""Writes mocap.csv, the motion capture the example replays: two real quadrotors, real0 and real1,
circling the virtual pillar at (2, 0) 1.2 m from its axis on opposite sides, 1.5 m up, at 0.5 rad/s,
seen at 100 Hz for 12 s; each turned to face along its path. A real system's jitter: stamps 0-2 ms
late, positions within 1 mm.

    make_mocap.py [OUT.csv]
    make_mocap.py OUT.csv --grid N SECONDS    (the benchmark's: real0..real<N-1> on a 2 m grid, ten to
                                               a row, each circling its place 0.3 m out, 1.5 m up)
"""
import math
import random
import sys

PILLAR = (2.0, 0.0)
RADIUS, HEIGHT, RATE, SPEED, SECONDS = 1.2, 1.5, 100, 0.5, 12.0


def rows():
    rng = random.Random(38)
    for k in range(int(SECONDS * RATE) + 1):
        for i, name in enumerate(("real0", "real1")):
            t = k / RATE + rng.uniform(0, 0.002)
            a = SPEED * t + math.pi * i
            x = PILLAR[0] + RADIUS * math.cos(a) + rng.uniform(-0.001, 0.001)
            y = PILLAR[1] + RADIUS * math.sin(a) + rng.uniform(-0.001, 0.001)
            yaw = a + math.pi / 2
            yield f"{t:.6f},{name},{x:.6f},{y:.6f},{HEIGHT:.6f},{math.cos(yaw / 2):.6f},0,0,{math.sin(yaw / 2):.6f}"


def grid_rows(n, seconds):
    rng = random.Random(38)
    for k in range(int(seconds * RATE) + 1):
        for i in range(n):
            t = k / RATE + rng.uniform(0, 0.002)
            a = SPEED * t + 0.7 * i
            x = 2.0 * (i % 10) + 0.3 * math.cos(a)
            y = 2.0 * (i // 10) + 0.3 * math.sin(a)
            yield f"{t:.6f},real{i},{x:.6f},{y:.6f},{HEIGHT:.6f},1,0,0,0"


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "mocap.csv"
    grid = len(sys.argv) == 5 and sys.argv[2] == "--grid"
    if len(sys.argv) > 2 and not grid:
        sys.exit(__doc__)
    with open(out, "w") as f:
        f.write("t,robot,x,y,z,qw,qx,qy,qz\n")
        for row in grid_rows(int(sys.argv[3]), float(sys.argv[4])) if grid else rows():
            f.write(row + "\n")


if __name__ == "__main__":
    main()
