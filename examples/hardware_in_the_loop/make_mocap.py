#!/usr/bin/env python3
"""Writes mocap.csv, the motion capture the example replays: two real quadrotors, real0 and real1,
circling the virtual pillar at (2, 0) 1.2 m from its axis on opposite sides, 1.5 m up, at 0.5 rad/s,
seen at 100 Hz for 12 s; each turned to face along its path. A real system's jitter: stamps 0-2 ms
late, positions within 1 mm.

    make_mocap.py [OUT.csv]
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


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "mocap.csv"
    with open(out, "w") as f:
        f.write("t,robot,x,y,z,qw,qx,qy,qz\n")
        for row in rows():
            f.write(row + "\n")


if __name__ == "__main__":
    main()
