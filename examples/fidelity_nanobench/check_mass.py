#!/usr/bin/python3
"""ssx_flight_replay's two ways of finding the take-off mass agree, it reads the dataset's own files
as it reads the trimmed copies, and --battery log changes the flights it should.

    check_mass.py PROGRAM DATA_DIR WORK_DIR

- On every flight with level cruise, the mass from the thrust command in level flight
  (--mass-from cruise) and from the vertical force balance over the whole flight (--mass-from
  balance) agree to 0.5 g; a flight without level cruise (helix, trefoil, the ramp) is refused by
  --mass-from cruise and flown by the default with the force balance.
- A copy of a trimmed flight under the dataset's own column names (sp_ctrltarget_x,
  pid_controller_cmd_thrust, motor_motor_m1, pwr_pm_vbat, ...) and its Unix-time clock gives the
  same mass and the same simulated flight."""
import pathlib
import re
import subprocess
import sys

import numpy as np

program, data, work = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
work.mkdir(parents=True, exist_ok=True)
problems = []


def replay(log, out, *options):
    run = subprocess.run([program, str(log), "--out", str(out), *options], capture_output=True, text=True)
    mass = re.search(r"take-off mass ([\d.]+) g", run.stdout)
    return run.returncode, float(mass.group(1)) if mass else None, run.stdout + run.stderr


flights = sorted(data.glob("B*_rep*.csv"))
if len(flights) != 22:
    problems.append(f"{data}: expected 22 flights, found {len(flights)}")
level = 0
for log in flights:
    rc_c, cruise, said_c = replay(log, work / "cruise.csv", "--mass-from", "cruise")
    rc_b, balance, said_b = replay(log, work / "balance.csv", "--mass-from", "balance")
    rc_a, auto, said_a = replay(log, work / "auto.csv")
    if rc_b != 0 or rc_a != 0:
        problems.append(f"{log.name}: not flown: {said_b.strip()} {said_a.strip()}")
        continue
    if rc_c == 0:
        level += 1
        print(f"{log.stem}: {cruise:.1f} g in level flight, {balance:.1f} g from the force balance")
        if abs(cruise - balance) > 0.5:
            problems.append(f"{log.stem}: {cruise} g in level flight against {balance} g from the force balance")
        if auto != cruise:
            problems.append(f"{log.stem}: the default took {auto} g, level flight gives {cruise} g")
    else:
        print(f"{log.stem}: no level cruise ({said_c.strip().splitlines()[-1]}); {balance:.1f} g from the force balance")
        if "error:" not in said_c or auto != balance or "vertical acceleration" not in said_a:
            problems.append(f"{log.stem}: without level cruise the default should use the force balance: {said_a}")
if level < 10:
    problems.append(f"only {level} flights with level cruise: the check compared too few")

# the dataset's own names and clock
names = {"sp_x": "sp_ctrltarget_x", "sp_y": "sp_ctrltarget_y", "sp_z": "sp_ctrltarget_z",
         "cmd_thrust": "pid_controller_cmd_thrust", "m1": "motor_motor_m1", "m2": "motor_motor_m2",
         "m3": "motor_motor_m3", "m4": "motor_motor_m4", "vbat": "pwr_pm_vbat"}
trimmed = data / "B5_helix_fast_rep1.csv"
lines = trimmed.read_text().splitlines()
header = [names.get(c, c) for c in lines[0].split(",")]
epoch = 1772424822.659
source = work / "B5_helix_fast_rep1_source_names.csv"
with open(source, "w") as f:
    f.write(",".join(header) + "\n")
    for line in lines[1:]:
        cells = line.split(",")
        f.write(",".join([f"{float(cells[0]) + epoch:.3f}", *cells[1:]]) + "\n")
_, m_trimmed, _ = replay(trimmed, work / "trimmed.csv")
rc, m_source, said = replay(source, work / "source.csv")
if rc != 0 or m_source != m_trimmed:
    problems.append(f"the dataset's names: rc {rc}, mass {m_source} g against {m_trimmed} g: {said}")
else:
    a = np.genfromtxt(work / "trimmed.csv", delimiter=",", names=True)
    b = np.genfromtxt(work / "source.csv", delimiter=",", names=True)
    if len(a) != len(b) or np.abs(b["t"] - epoch - a["t"]).max() > 1.5e-3:
        problems.append("the dataset's names: another time axis")
    else:
        worst = max(np.abs(a[k] - b[k]).max() for k in ("px", "py", "pz"))
        print(f"the dataset's own names: {m_source} g, the simulated positions within {worst * 1e3:.2f} mm of the trimmed copy's")
        if worst > 1e-3:
            problems.append(f"the dataset's names: positions differ by {worst} m")
# --battery log: the logged voltage row by row changes the ramp (flown on a battery at 2.85-3.06 V)
# and nothing of a fast eight on 3.23-3.35 V (the firmware's full command needs about 3.1 V a motor)
for name, changes in (("B6_linear_ramp_rep1", True), ("B3_figure8_fast_rep2", False)):
    flown = []
    for battery in ("median", "log"):
        rc, _, said = replay(data / f"{name}.csv", work / f"battery_{battery}.csv", "--battery", battery)
        if rc != 0:
            problems.append(f"{name} --battery {battery}: {said}")
            break
        flown.append(np.genfromtxt(work / f"battery_{battery}.csv", delimiter=",", names=True))
    else:
        worst = max(np.abs(flown[0][k] - flown[1][k]).max() for k in ("px", "py", "pz"))
        print(f"{name}: the logged voltage row by row moves the flight by up to {worst * 1e3:.2f} mm")
        if (worst > 1e-3) != changes:
            problems.append(f"{name}: --battery log moved it by {worst} m; expected {'a change' if changes else 'none'}")
# --rotor-factors log: the fast eight on its weak battery, whose motor 1 carried 0.77 of the mean and
# motor 4 1.2 of it (1 / share each), flies with them
run = subprocess.run([program, str(data / "B3_figure8_fast_rep2.csv"), "--out", str(work / "factors.csv"),
                      "--rotor-factors", "log"], capture_output=True, text=True)
factors = re.search(r"rotor thrust factors ([\d.]+) ([\d.]+) ([\d.]+) ([\d.]+)", run.stdout)
if run.returncode != 0 or not factors:
    problems.append(f"--rotor-factors log: {run.stdout} {run.stderr}")
else:
    k = [float(x) for x in factors.groups()]
    flown = np.genfromtxt(work / "factors.csv", delimiter=",", names=True)
    print(f"B3_figure8_fast_rep2: rotor thrust factors {k}, flown up to {flown['pz'].max():.3f} m")
    if not (k[0] > 1.2 and k[3] < 0.9 and abs(np.mean([1 / x for x in k]) - 1) < 1e-3) or flown["pz"].max() > 1.5:
        problems.append(f"--rotor-factors log: factors {k}, highest {flown['pz'].max()} m")
print("\n".join(problems) if problems else "both ways of finding the mass agree; the dataset's own files are read; "
      "the logged voltage and the rotors' factors do what they should")
sys.exit(1 if problems else 0)
