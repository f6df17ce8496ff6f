#!/usr/bin/env python3
"""ctest (plugins/foxglove/foxglove.cpp): Foxglove's own client library talks to `ssx run --foxglove`.

    foxglove_test.py SSX SCENE ROBOT NPM_DIR WORK_DIR

Runs SCENE in real time with `--foxglove 0` (a free port, read from the line the run prints) and
`--record` at every step; tests/tools/foxglove_client.mjs (@foxglove/ws-protocol's FoxgloveClient,
installed in NPM_DIR by `./dev.sh test`) connects, subscribes and decodes for a few seconds. Then:
- the server's information offers the `time` capability, and every channel is JSON with a JSON
  Schema that parses, the recording's topics among them and ROBOT's own (odom, imu, command, sensors, metrics);
- every subscribed channel delivered messages, stamped with simulated time, and time messages came;
- /scene holds an entity for ROBOT; /ssx/run's time agrees with its stamp, /ssx/timing names steps;
- every /tf message equals the recording's /tf at the same simulated time (every body, within 1e-6 m:
  both are the simulation's float poses), and /ROBOT/odom's position equals it within 1e-5 m (at
  least 3 of each: a real-time run's recorder drops samples when its writer falls behind, and a
  loaded machine sends fewer messages);
- ROBOT's own /ROBOT/imu, /ROBOT/command and /ROBOT/sensors equal what /ssx/sensors and
  /ssx/commands hold for it at the same stamp (at least 3 of each), and /ROBOT/metrics are its
  driver's numbers;
- the run's closing line counts what was sent and no client refused.
Exit status 1 with what differs.
"""
import json
import pathlib
import re
import shutil
import subprocess
import sys
import time

ssx, scene, robot, npm, work = sys.argv[1], sys.argv[2], sys.argv[3], pathlib.Path(sys.argv[4]), pathlib.Path(sys.argv[5])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
for package in ("@foxglove/ws-protocol", "ws", "@mcap/core"):
    if not (npm / "node_modules" / package).is_dir():
        sys.exit(f"{npm}/node_modules/{package} is missing: ./dev.sh test installs it "
                 f"(or: cp tests/tools/package*.json {npm}/ && npm ci --prefix {npm})")
client = npm / "foxglove_client.mjs"
shutil.copy(pathlib.Path(__file__).parents[2] / "tools" / "foxglove_client.mjs", client)
recording = work / "run.mcap"
problems = []

run = subprocess.Popen([ssx, "run", scene, "--realtime", "--duration", "6", "--foxglove", "0", "--record", str(recording),
                        "--record-rate", "0", "--quiet"], cwd=work, stderr=subprocess.PIPE, text=True)
url = None
lines = []
deadline = time.monotonic() + 30
while url is None and time.monotonic() < deadline:
    line = run.stderr.readline()
    if not line:
        break
    lines.append(line)
    m = re.search(r"foxglove: (ws://127\.0\.0\.1:\d+)", line)
    if m:
        url = m.group(1)
if url is None:
    run.kill()
    sys.exit("the run printed no Foxglove address:\n" + "".join(lines))
live = subprocess.run(["node", str(client), "live", url, "3", robot], capture_output=True, text=True, timeout=60)
rest = run.communicate(timeout=60)[1]
lines.append(rest)
if live.returncode != 0:
    sys.exit(f"foxglove_client.mjs live: exit {live.returncode}\n{live.stderr}")
if run.returncode != 0:
    sys.exit(f"ssx run: exit {run.returncode}\n{''.join(lines)}")
got = json.loads(live.stdout)

# the server and its channels
info = got["serverInfo"] or {}
if "time" not in info.get("capabilities", []):
    problems.append(f"serverInfo offers no 'time' capability: {info}")
topics = {c["topic"]: c for c in got["channels"]}
for topic, schema in [("/tf", "foxglove.FrameTransforms"), ("/scene", "foxglove.SceneUpdate"), ("/ssx/timing", "ssx.StepTiming"),
                      ("/ssx/sensors", "ssx.Sensors"), ("/ssx/commands", "ssx.Commands"), ("/ssx/run", "ssx.RunStatus"),
                      (f"/{robot}/odom", "ssx.Odometry"), (f"/{robot}/imu", "ssx.Imu"), (f"/{robot}/command", "ssx.Command"),
                      (f"/{robot}/sensors", "ssx.RobotSensors"), (f"/{robot}/metrics", "ssx.Metrics")]:
    c = topics.get(topic)
    if c is None:
        problems.append(f"{topic} is not advertised (channels: {sorted(topics)[:10]}...)")
    elif c["encoding"] != "json" or c["schemaName"] != schema or c["schemaEncoding"] != "jsonschema" or not c["schemaParses"]:
        problems.append(f"{topic}: {c}, expected JSON with the JSON Schema {schema}")
    elif not got["messages"].get(topic):
        problems.append(f"{topic}: subscribed, no message came")
if got["times"] < 10:
    problems.append(f"{got['times']} time messages in 3 s (at 30 Hz: about 90)")
if got["badMessages"] or got["statuses"]:
    problems.append(f"{got['badMessages']} messages that are not JSON, statuses {got['statuses']}")
messages = got["messages"]

# what they hold
scene_update = (messages.get("/scene") or [[0, {"entities": []}]])[0][1]
if robot not in [e["frame_id"] for e in scene_update["entities"]]:
    problems.append(f"/scene holds no entity in the frame of {robot}")
for stamp, value in messages.get("/ssx/run", []):
    if abs(value["time"] - int(stamp) / 1e9) > 1e-9 or not 0 <= value["realtime_factor"] < 10:
        problems.append(f"/ssx/run at {stamp} ns: {value}")
        break
if not all("step" in v and "total_ms" in v for _, v in messages.get("/ssx/timing", [])):
    problems.append("/ssx/timing: a message without its step and cost")

# the same values as the simulation: the recording of the same run, every step
recorded = json.loads(subprocess.run(["node", str(client), "tf", str(recording)], capture_output=True, text=True,
                                     check=True).stdout)
at = {int(t): frames for t, frames in recorded}
compared = unmatched = 0
for stamp, value in messages.get("/tf", []):
    t = int(stamp)
    frames = at.get(t)
    if frames is None:  # (a real-time run's recorder drops samples when its writer falls behind)
        unmatched += 1
        continue
    live_frames = {x["child_frame_id"]: [x["translation"][k] for k in "xyz"] for x in value["transforms"]}
    if sorted(live_frames) != sorted(frames):
        problems.append(f"/tf at {t} ns: frames {sorted(live_frames)[:5]}..., the recording's {sorted(frames)[:5]}...")
        break
    worst = max(abs(a - b) for name in frames for a, b in zip(live_frames[name], frames[name]))
    if worst > 1e-6:
        problems.append(f"/tf at {t} ns: {worst:.3g} m from the recording's")
        break
    compared += 1
odometry = 0
for stamp, value in messages.get(f"/{robot}/odom", []):
    frames = at.get(int(stamp))
    p = value["position"]
    if frames is None:
        continue
    odometry += 1
    if max(abs(p[k] - v) for k, v in zip("xyz", frames[robot])) > 1e-5:
        problems.append(f"/{robot}/odom at {stamp} ns: {p}, the recording's {frames and frames[robot]}")
        break
    if int(stamp) != value["timestamp"]["sec"] * 10**9 + value["timestamp"]["nsec"]:
        problems.append(f"/{robot}/odom at {stamp} ns stamped {value['timestamp']}")
        break
if compared < 3 or odometry < 3:
    problems.append(f"only {compared} /tf and {odometry} odometry messages compared with the recording "
                    f"({unmatched} at times the recording dropped)")

# the robot's own channels hold what the swarm's hold for it in the same snapshot (the same stamp):
# its IMU (the first sensor of kind imu), its command and all its sensors; its metrics are numbers
swarm_sensors = {int(t): v for t, v in messages.get("/ssx/sensors", [])}
swarm_commands = {int(t): v for t, v in messages.get("/ssx/commands", [])}
matched = {"imu": 0, "command": 0, "sensors": 0}
for stamp, value in messages.get(f"/{robot}/imu", []):
    entry = swarm_sensors.get(int(stamp), {}).get(robot)
    if entry is None:
        continue
    imu = next(m for _, m in sorted(entry.items(), key=lambda kv: int(kv[0])) if m["kind"] == "imu")
    ours = [value[f][k] for f in ("accelerometer", "gyroscope") for k in "xyz"]
    if ours != imu["accelerometer"] + imu["gyroscope"] or abs(value["timestamp"]["sec"] + value["timestamp"]["nsec"] / 1e9 - imu["stamp"]) > 1e-6:
        problems.append(f"/{robot}/imu at {stamp} ns: {value}, /ssx/sensors has {imu}")
        break
    matched["imu"] += 1
for own, swarm, by_stamp in (("command", "/ssx/commands", swarm_commands), ("sensors", "/ssx/sensors", swarm_sensors)):
    for stamp, value in messages.get(f"/{robot}/{own}", []):
        theirs = by_stamp.get(int(stamp), {}).get(robot)
        if theirs is None:
            continue
        if value != theirs:
            problems.append(f"/{robot}/{own} at {stamp} ns: {value}, {swarm} has {theirs}")
            break
        matched[own] += 1
if min(matched.values()) < 3:
    problems.append(f"the robot's own channels matched with the swarm's at the same stamp: {matched} (at least 3 each)")
metrics = [v for _, v in messages.get(f"/{robot}/metrics", [])]
if not metrics or not all(isinstance(v, dict) and v and all(x is None or isinstance(x, (int, float)) for x in v.values())
                          for v in metrics):
    problems.append(f"/{robot}/metrics: {metrics[:3]} (objects of numbers, the driver's metrics)")

closing = re.search(r"foxglove: (\d+) messages published, (\d+) sent, .* (\d+) clients refused", "".join(lines))
if not closing or int(closing.group(2)) == 0 or int(closing.group(3)) != 0:
    problems.append("the run's closing line: " + (closing.group(0) if closing else "missing"))

print(f"{len(got['channels'])} channels, {got['times']} time messages, "
      + ", ".join(f"{t} {len(v)}" for t, v in sorted(messages.items()))
      + f"; {compared} /tf messages equal to the recording's ({unmatched} at times it dropped); "
      f"the robot's own equal to the swarm's: {matched}")
for p in problems:
    print("error:", p)
sys.exit(1 if problems else 0)
