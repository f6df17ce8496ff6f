#!/usr/bin/env python3
"""A recording read by an independent MCAP reader agrees with what ssx says it wrote.

    check_recording.py SSX SCENE NPM_DIR WORK_DIR

Records SCENE with `ssx run --record`, reads the file with Foxglove's @mcap/core (NPM_DIR holds it,
installed by `./dev.sh test` with `npm ci`; mcap_check.mjs beside this script is copied there) and
compares channels, message counts, time span, attachments and metadata with `ssx inspect --json`.
The run also records Foxglove's /tf and /scene and the timing and sensor channels: every JSON message
and schema must parse, /tf must hold a transform from "world" to every body at every pose sample and
/scene an entity locked to each body. Then cuts the file in half (a killed run), has `ssx inspect --complete` write a complete copy and
checks that copy the same way. Exit status 1 with the differences when anything disagrees.
"""
import json
import pathlib
import shutil
import subprocess
import sys

ssx, scene, npm, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3]), pathlib.Path(sys.argv[4])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
if not (npm / "node_modules" / "@mcap" / "core").is_dir():
    sys.exit(f"{npm}/node_modules/@mcap/core is missing: ./dev.sh test installs it "
             f"(or: cp tests/tools/package*.json {npm}/ && npm ci --prefix {npm})")
shutil.copy(pathlib.Path(__file__).with_name("mcap_check.mjs"), npm / "mcap_check.mjs")
problems = []


def run(*args):
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(map(str, args))}: exit {r.returncode}\n{r.stdout}{r.stderr}")
    return r.stdout


def compare(file, expect_samples=None):
    ours = json.loads(run(ssx, "inspect", str(file), "--json"))
    theirs = json.loads(run("node", str(npm / "mcap_check.mjs"), str(file)))
    where = file.name

    def check(what, mine, other):
        if mine != other:
            problems.append(f"{where}: {what}: ssx says {mine!r}, @mcap/core reads {other!r}")

    check("complete", ours["complete"], True)
    check("profile", "ssx", theirs["profile"])
    check("channels", sorted(ours["channels"]), sorted(theirs["channels"]))
    for topic, count in ours["channels"].items():
        if topic in theirs["channels"]:
            check(f"messages on {topic}", count, theirs["channels"][topic]["count"])
    check("schema of /ssx/poses", "ssx.Poses", theirs["channels"].get("/ssx/poses", {}).get("schema"))
    total = sum(ours["channels"].values())
    check("messages read record by record (CRCs checked)", total, theirs["streamedMessages"])
    check("message count in the statistics", str(total), theirs["statisticsMessageCount"])
    check("footer", True, theirs["footer"] and theirs["done"])
    poses = theirs["channels"].get("/ssx/poses", {})
    check("first pose sample's time", str(ours["first_time_ns"]), poses.get("firstTime"))
    check("last pose sample's time", str(ours["last_time_ns"]), poses.get("lastTime"))
    # the file's span: from the first step's timing (2 ms) to the last pose sample
    check("first message time", str(min(int(c["firstTime"]) for c in theirs["channels"].values() if "firstTime" in c)),
          theirs["firstTime"])
    check("last message time", str(max(int(ours["last_time_ns"]), *(int(c["lastTime"]) for c in theirs["channels"].values() if "lastTime" in c))),
          theirs["lastTime"])
    names = sorted(a["name"] for a in theirs["attachments"])
    check("attachments", sorted(["scene.xml"] + [f"state/{t}" for t in ours["states_ns"]]), names)
    check("metadata", ["ssx", "ssx.bodies"], sorted(m["name"] for m in theirs["metadata"]))
    if expect_samples is not None:
        check("pose samples", expect_samples, ours["channels"].get("/ssx/poses"))
    # the JSON channels, parsed by Node
    j = theirs["json"]
    check("JSON messages that do not parse", 0, j["badMessages"])
    for topic, c in theirs["channels"].items():
        if c["messageEncoding"] == "json":
            check(f"JSON Schema title of {topic}", c["schema"], c.get("schemaTitle", c.get("schemaError")))
    check("schema of /tf", "foxglove.FrameTransforms", theirs["channels"].get("/tf", {}).get("schema"))
    check("schema of /scene", "foxglove.SceneUpdate", theirs["channels"].get("/scene", {}).get("schema"))
    check("/tf messages", ours["channels"].get("/ssx/poses"), ours["channels"].get("/tf"))
    check("transforms in each /tf message", [ours["bodies"]] * len(j["tfSizes"]), j["tfSizes"])
    check("/tf parent frames", ["world"], j["tfParents"])
    check("/tf child frames", ours["names"], j["tfFrames"])
    entities = {e["id"]: e for e in j["sceneEntities"] or []}
    for name in ours["names"]:
        e = entities.get(name)
        check(f"/scene entity of {name} (frame, locked, has shapes)", (name, True, True),
              (e["frame"], e["locked"], e["primitives"] > 0) if e else None)
    check("/ssx/timing steps", list(range(len(j["timingSteps"]))), j["timingSteps"])
    check("/ssx/sensors artifacts with measurements", ours["bodies"], j["sensorArtifacts"])
    check("/ssx/commands messages", ours["channels"].get("/ssx/poses"), ours["channels"].get("/ssx/commands"))
    return ours


recording = work / "run.mcap"
out = run(ssx, "run", scene, "--steps", "1500", "--fast", "--record", str(recording), "--out", str(work / "out"),
          "--record-channels", "foxglove,timing,sensors,commands")
if "recording " not in out:
    problems.append(f"ssx run printed no recording line:\n{out}")
ours = compare(recording, expect_samples=75)  # 3 s at 25 samples per simulated second
if ours["channels"].get("/ssx/timing") != 1500:
    problems.append(f"/ssx/timing holds {ours['channels'].get('/ssx/timing')} messages, the run made 1500 steps")

# a run killed half way: the first half of the file, completed
data = recording.read_bytes()
cut = work / "cut.mcap"
cut.write_bytes(data[: len(data) // 2])
fixed = work / "completed.mcap"
run(ssx, "inspect", str(cut), "--complete", str(fixed))
completed = compare(fixed)
if not 0 < completed["channels"]["/ssx/poses"] < 75:
    problems.append(f"the completed half holds {completed['channels']['/ssx/poses']} of 75 samples")

print("\n".join(problems) if problems else
      f"@mcap/core reads both files as ssx wrote them: {ours['channels']['/ssx/poses']} and "
      f"{completed['channels']['/ssx/poses']} pose samples, {len(ours['states_ns'])} saved state(s)")
sys.exit(1 if problems else 0)
