#!/usr/bin/python3
"""The trimmed real flights score as data/README.md's table says (the scores of the dataset's own
files): mean, lag, distance after the lag and max, to 0.1 mm (the max, one sample, to 0.5 mm) and 0.01 s. Fails on a flight missing
from the table or the directory, and on any score that differs.

    check_real_flights.py DATA_DIR"""
import pathlib
import re
import subprocess
import sys

here = pathlib.Path(__file__).resolve().parent
data = pathlib.Path(sys.argv[1])
table = {}
for line in (data / "README.md").read_text().splitlines():
    m = re.match(r"\| (B\d+_\w+) \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \|", line)
    if m:
        table[m.group(1)] = [float(x) for x in m.groups()[1:]]
flights = sorted(p.stem for p in data.glob("B*_rep*.csv"))
problems = []
if sorted(table) != flights or len(flights) != 22:
    problems.append(f"the table lists {sorted(table)}, the directory holds {flights}")
scored = subprocess.run([sys.executable, str(here / "score_flight.py"), *[str(data / f"{f}.csv") for f in flights]],
                        capture_output=True, text=True, check=True).stdout
for line in scored.splitlines():
    m = re.search(r"file=(\S+)\.csv .*mean_m=([\d.]+) .*lag_s=([\d.]+) mean_after_lag_m=([\d.]+) max_m=([\d.]+)", line)
    if not m or m.group(1) not in table:
        continue
    got = [float(x) for x in m.groups()[1:]]
    want = table[m.group(1)]
    print(f"{m.group(1)}: mean {got[0]:.4f} m, lag {got[1]:.2f} s, after the lag {got[2]:.4f} m, max {got[3]:.4f} m")
    for name, g, w, tolerance in zip(("mean", "lag", "after the lag", "max"), got, want, (1.5e-4, 0.005, 1.5e-4, 5e-4)):
        if abs(g - w) > tolerance:
            problems.append(f"{m.group(1)}: {name} {g}, the table says {w}")
print("\n".join(problems) if problems else "every real flight scores as the table says")
sys.exit(1 if problems else 0)
