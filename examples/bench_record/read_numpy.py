#!/usr/bin/env python3
"""Times reading every pose of a recording into numpy (ssx.Recording: positions and orientations).

    read_numpy.py FILE [REPEATS]

Prints: samples=T bodies=N read_s=... (the fastest of REPEATS reads, default 3, each opening the file anew)."""
import sys
import time

import ssx

file = sys.argv[1]
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 3
best = float("inf")
for _ in range(repeats):
    t0 = time.perf_counter()
    r = ssx.Recording(file)
    p, q = r.positions(), r.orientations()
    best = min(best, time.perf_counter() - t0)
print(f"samples={p.shape[0]} bodies={p.shape[1]} simulated_s={r.times[-1] - r.times[0]:.2f} read_s={best:.2f} "
      f"bytes={r.size}")
