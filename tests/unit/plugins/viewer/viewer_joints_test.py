#!/usr/bin/env python3
"""The viewer draws a robot's joined parts as bodies of their own (python3-websockets, loopback).

    viewer_joints_test.py SSX EXAMPLES_DIR WORK_DIR

The landing scene (a TurtleBot3 Burger whose wheels turn on hinges, a Crazyflie) runs in real time
with --view; a page's scene lists the Burger's chassis, both wheels and its caster as bodies, each
wheel with its own cylinder (the chassis without them), and every frame carries a pose per body:
each wheel beside the chassis (8 cm to its side), turning as the Burger drives.
Exits 77 when python3-websockets is not installed."""
import asyncio
import json
import math
import pathlib
import shutil
import struct
import sys

from viewer_util import ViewedRun

try:
    import websockets
except ImportError:
    print("python3-websockets is not installed: skipped")
    sys.exit(77)

ssx, examples, work = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
problems = []


async def main(url):
    async with websockets.connect(url.replace("http://", "ws://").rstrip("/") + "/ws", max_size=None) as page:
        await page.send('{"type":"hello"}')
        scene, frames = None, []
        while len(frames) < 20:
            message = await asyncio.wait_for(page.recv(), 30)
            if isinstance(message, str):
                scene = json.loads(message) if json.loads(message).get("type") == "scene" else scene
                continue
            if scene is None or not scene["bodies"]:
                continue
            _, n, t = struct.unpack_from("<IId", message)
            poses = [struct.unpack_from("<7f", message, 32 + 28 * i) for i in range(n)]
            frames.append((t, poses))
    names = [b["name"] for b in scene["bodies"]]
    want = ["burger", "burger/left_wheel", "burger/right_wheel", "burger/caster", "cf"]
    if names != want:
        problems.append(f"bodies {names}, not {want}")
        return
    models = {name: scene["models"][b["model"]] for name, b in zip(names, scene["bodies"])}
    for wheel in ("burger/left_wheel", "burger/right_wheel"):
        shapes = models[wheel]
        if len(shapes) != 1 or shapes[0]["kind"] != "cylinder" or abs(shapes[0]["radius"] - 0.033) > 1e-9:
            problems.append(f"{wheel}: shapes {shapes}, not its cylinder")
    if any(abs(s["radius"] - 0.033) < 1e-9 for s in models["burger"]):
        problems.append("the chassis carries a wheel's cylinder")
    turned = 0.0
    for t, poses in frames:
        chassis, left = poses[0], poses[1]
        side = math.dist(chassis[:2], left[:2])
        if abs(side - 0.08) > 0.005:
            problems.append(f"at {t:.2f} s the left wheel is {side:.3f} m from the chassis, not 0.08 m")
            break
    first, last = frames[0][1][1], frames[-1][1][1]
    turned = abs(sum(a * b for a, b in zip(first[3:], last[3:])))
    if frames[-1][0] - frames[0][0] > 0.3 and turned > 0.9999:
        problems.append(f"the left wheel did not turn from {frames[0][0]:.2f} s to {frames[-1][0]:.2f} s")


run = ViewedRun(ssx, str(examples / "ground" / "landing.xml"), str(work))
try:
    asyncio.run(main(run.url))
finally:
    status, err = run.stop()
if status not in (0, 130):  # (130: stopped by Ctrl-C, as a person stops it)
    problems.append(f"ssx exited with {status}:\n{err}")
for p in problems:
    print("FAILED:", p)
sys.exit(1 if problems else 0)
