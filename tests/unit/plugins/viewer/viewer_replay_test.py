#!/usr/bin/env python3
"""`ssx replay FILE --view` against its protocol (python3-websockets), on loopback: a recording of
200 light robots (6 s) is played on a page. Passes when the page gets the recorded scene with the
recording's span ("replay": start and end), frames of exactly the recorded poses (compared with
ssx.Recording: positions, and orientations turned from w x y z into the frame's x y z w), its clock
going with the wall clock at speed 1 and four times as fast at speed 4, pause holding it, a step
going one sample on, a seek landing on the sample at or before the time asked; a velocity command
is dropped (nothing to steer in a recording), and Ctrl-C ends it with status 130. Then, with
Chromium and selenium installed, the page itself: every robot, the 50 nearest the camera in full and
the others as dots when asked for 50 (?full=50), the time slider over the recording's span and no
steering; paused from the page and the slider moved to 3 s, the page shows the sample
at or before 3 s.

    viewer_replay_test.py SSX EXAMPLES_DIR PYTHON_DIR WORK_DIR

PYTHON_DIR "-" (a sanitized build, which has no Python module): the poses are not compared with
the recording, and the test says so.

Exits 77 when python3-websockets is not installed."""
import asyncio
import json
import pathlib
import re
import shutil
import struct
import subprocess
import sys
import time

from viewer_util import ViewedRun

try:
    import websockets
except ImportError:
    print("python3-websockets is not installed: skipped")
    sys.exit(77)

ssx, examples, work = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[4])
ssx_module = None
if sys.argv[3] != "-":
    sys.path.insert(0, sys.argv[3])
    import ssx as ssx_module  # noqa: E402  (the build's module)

shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
scene = work / "swarm.xml"
scene.write_text(f"""<scene><environment timestep="0.01" seed="1"/>
  <type name="r" file="{examples / 'artifacts' / 'hover_body.xml'}"/><ground/>
  <swarm type="r" count="200" name="r{{i}}" layout="random" min="-8 -8 0.5" max="8 8 3" min_distance="0.8"/></scene>""")
recording = work / "run.mcap"
made = subprocess.run([ssx, "run", str(scene), "--fast", "--duration", "6", "--record", str(recording), "--out",
                       str(work / "out")], capture_output=True, text=True, timeout=120)
if made.returncode != 0:
    sys.exit(f"the recording was not made:\n{made.stderr[-2000:]}")
if ssx_module:
    r = ssx_module.Recording(str(recording))
    names, times, positions, orientations = list(r.names), list(r.times), r.positions(), r.orientations()
else:  # what `ssx inspect --json` says: names and times (25 samples a second)
    info = json.loads(subprocess.run([ssx, "inspect", str(recording), "--json"], capture_output=True, text=True,
                                     check=True).stdout)
    names = info["names"]
    times = [t / 1e9 for t in range(info["first_time_ns"], info["last_time_ns"] + 1, 40_000_000)]
    positions = orientations = None
    print("no Python module (a sanitized build): the poses are not compared with the recording")
interval = times[1] - times[0]
problems = []


async def frame(ws):
    """The next frame: (time, rate, sample, floats of the poses)."""
    while True:
        message = await asyncio.wait_for(ws.recv(), 10)
        if isinstance(message, bytes):
            magic, n, t, rate, late, sample = struct.unpack_from("<IIdfIQ", message)
            return t, rate, sample, struct.unpack_from(f"<{7 * n}f", message, 32)


async def newest(ws, seconds=0.4):
    """The newest frame after `seconds` of reading everything that came."""
    loop = asyncio.get_running_loop()
    end, last = loop.time() + seconds, await frame(ws)
    while loop.time() < end:
        try:
            last = await asyncio.wait_for(frame(ws), max(0.01, end - loop.time()))
        except asyncio.TimeoutError:
            break
    return last


def difference(f):
    """The largest difference between a frame's poses and its sample's in the recording."""
    t, rate, k, floats = f
    worst = abs(t - times[k])
    if positions is None:
        return worst
    for i in range(len(names)):
        x = floats[7 * i:7 * i + 7]
        p, q = positions[k][i], orientations[k][i]
        worst = max(worst, max(abs(x[a] - p[a]) for a in range(3)), max(abs(x[3 + a] - q[1 + a]) for a in range(3)),
                    abs(x[6] - q[0]))
    return worst


async def main(url):
    async with websockets.connect(url.replace("http://", "ws://").rstrip("/") + "/ws", max_size=None) as ws:
        description = json.loads(await asyncio.wait_for(ws.recv(), 10))
        while "bodies" not in description or not description["bodies"]:
            description = json.loads(await asyncio.wait_for(ws.recv(), 10))
        span = description.get("replay")
        if not span or abs(span["start"] - times[0]) > 1e-4 or abs(span["end"] - times[-1]) > 1e-4:
            problems.append(f"the scene's replay span {span}, the recording's {times[0]} to {times[-1]}")
        if [b["name"] for b in description["bodies"]] != names:
            problems.append("the page's bodies are not the recording's, in its order")
        # the poses are the recorded ones
        first = await frame(ws)
        if difference(first) > 1e-6:
            problems.append(f"the frame of sample {first[2]} differs from the recording by {difference(first)}")
        # speed 1: the clock goes with the wall clock
        a, wall_a = await newest(ws), time.monotonic()
        await asyncio.sleep(1.5)
        b, wall_b = await newest(ws), time.monotonic()
        print(f"at speed 1: {b[0] - a[0]:.2f} s played in {wall_b - wall_a:.2f} s")
        if abs((b[0] - a[0]) - (wall_b - wall_a)) > 0.3:
            problems.append(f"at speed 1, {b[0] - a[0]:.2f} s played in {wall_b - wall_a:.2f} s")
        # pause: held; a seek lands on the sample at or before; a step goes one sample on
        await ws.send('{"type":"pause"}')
        held = await newest(ws, 0.5)
        again = await newest(ws, 1.2)
        if held[1] != 0 or again[0] != held[0]:
            problems.append(f"paused, the frames went from {held[0]} to {again[0]} (rate {held[1]})")
        await ws.send('{"type":"seek","time":2.013}')
        sought = await newest(ws, 0.5)
        expected = max(x for x in times if x <= 2.013)
        if abs(sought[0] - expected) > 1e-9:
            problems.append(f"sent to 2.013 s, the page shows {sought[0]} ({expected} expected)")
        await ws.send('{"type":"step"}')
        stepped = await newest(ws, 0.5)
        if abs(stepped[0] - (expected + interval)) > 1e-6:
            problems.append(f"one step from {expected} went to {stepped[0]} (samples every {interval} s)")
        if positions is not None:
            print(f"samples {first[2]} and {stepped[2]}: largest difference from the recording "
                  f"{max(difference(first), difference(stepped)):.2e}")
        if difference(stepped) > 1e-6:
            problems.append(f"the frame of sample {stepped[2]} differs from the recording by {difference(stepped)}")
        # speed 4 from the start
        await ws.send('{"type":"seek","time":0}')
        await ws.send('{"type":"rate","factor":4}')
        await ws.send('{"type":"resume"}')
        await ws.send('{"type":"velocity","body":0,"v":[1,0,0],"yaw_rate":0}')  # dropped
        a, wall_a = await newest(ws, 0.3), time.monotonic()
        await asyncio.sleep(0.75)
        b, wall_b = await newest(ws, 0.3), time.monotonic()
        print(f"at speed 4: {b[0] - a[0]:.2f} s played in {wall_b - wall_a:.2f} s")
        if abs((b[0] - a[0]) - 4 * (wall_b - wall_a)) > 0.8:
            problems.append(f"at speed 4, {b[0] - a[0]:.2f} s played in {wall_b - wall_a:.2f} s")


run = ViewedRun(ssx, None, None, replay=str(recording))
try:
    asyncio.run(main(run.url))
finally:
    status, err = run.stop()
if status != 130:
    problems.append(f"ssx replay --view ended with status {status} after Ctrl-C (130 expected):\n{err[-2000:]}")
dropped = re.search(r"(\d+) messages dropped", err)
if not dropped or int(dropped.group(1)) != 1:
    problems.append(f"the velocity command was not the one message dropped:\n{err[-2000:]}")


def in_browser():
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.options import Options
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        return print("selenium is not installed: the page in a browser not tried")
    from viewer_util import chromium_available
    if not chromium_available():
        return print("chromium is not installed: the page in a browser not tried")
    options = Options()
    for a in ("--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
              "--window-size=1024,700", f"--user-data-dir={work}/profile"):
        options.add_argument(a)
    page = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    played = ViewedRun(ssx, None, None, replay=str(recording))
    try:
        page.get(played.url + "?full=50")  # the 50 nearest robots in full, the others as dots
        deadline = time.monotonic() + 60
        while page.execute_script("return document.getElementById('robots').textContent") != str(len(names)):
            if time.monotonic() > deadline:
                return problems.append("the page never showed the recording's robots")
            time.sleep(0.2)
        shown = page.execute_script("""const s = document.getElementById('slider');
            return [document.getElementById('replay').hidden, document.getElementById('steer').hidden,
                    Number(s.min), Number(s.max)]""")
        print(f"the page: slider hidden {shown[0]}, steering hidden {shown[1]}, slider {shown[2]} to {shown[3]} s")
        if shown[0] or not shown[1] or abs(shown[2] - times[0]) > 1e-3 or abs(shown[3] - times[-1]) > 1e-3:
            problems.append(f"the page's slider and steering: {shown}")
        near = page.execute_script("""const v = window.ssxViewer, m = v.state.models[0], c = v.camera.position;
            const p = v.state.positions, d = (i) => Math.hypot(p[7 * i] - c.x, p[7 * i + 1] - c.y, p[7 * i + 2] - c.z);
            const full = Array.from(m.full.slice(0, m.parts[0].mesh.count));
            const far = Array.from(m.far.slice(0, m.points.geometry.drawRange.count));
            return [full.length, far.length, Math.max(...full.map(d)), Math.min(...far.map(d)),
                    new Set([...full, ...far]).size]""")
        print(f"?full=50: {near[0]} robots in full up to {near[2]:.2f} m from the camera, {near[1]} as dots from "
              f"{near[3]:.2f} m, {near[4]} different robots")
        if near[0] != 50 or near[1] != len(names) - 50 or near[2] > near[3] or near[4] != len(names):
            problems.append(f"with ?full=50 the page drew {near}")
        page.find_element("id", "pause").click()
        page.execute_script("""const s = document.getElementById('slider'); s.value = 3;
                               s.dispatchEvent(new Event('input'));""")
        expected = max(x for x in times if x <= 3.0)
        deadline, at = time.monotonic() + 10, None
        while time.monotonic() < deadline:
            at = float(page.execute_script("return document.getElementById('time').textContent"))
            if abs(at - expected) < 5e-4:
                break
            time.sleep(0.1)
        print(f"slider to 3 s: the page shows {at:.3f} s ({expected:.3f} expected)")
        if abs(at - expected) >= 5e-4:
            problems.append(f"the slider moved to 3 s, the page shows {at} s ({expected} expected)")
    finally:
        page.quit()
        played.stop()


in_browser()

# A robot selected in a replay of a run recorded with its sensors and commands: its details come with
# the frames as the recording has them at the sample shown (the command, the IMU), and the page's
# panel shows them.
quads = work / "quads.xml"
quads.write_text(f"""<scene><environment timestep="0.002" seed="2"/>
  <type name="q" file="{examples / 'artifacts' / 'mk_quad.xml'}"/><ground/>
  <swarm type="q" count="3" name="q{{i}}" spacing="1.5" xyz="0 0 0.05"><driver offset="0 0 1"/></swarm></scene>""")
detailed = work / "quads.mcap"
made = subprocess.run([ssx, "run", str(quads), "--fast", "--duration", "3", "--record", str(detailed),
                       "--record-channels", "sensors,commands", "--out", str(work / "out_quads")],
                      capture_output=True, text=True, timeout=120)
if made.returncode != 0:
    sys.exit(f"the recording with sensors was not made:\n{made.stderr[-2000:]}")


async def details_of(url):
    """The details of body 1 with the first frame that has them, paused at 2 s: (frame time, details)."""
    async with websockets.connect(url.replace("http://", "ws://").rstrip("/") + "/ws", max_size=None) as ws:
        # (the first frame first: the recording's bodies are known from then on; what comes before,
        # on a loaded machine, may be dropped)
        while not isinstance(await asyncio.wait_for(ws.recv(), 30), bytes):
            pass
        await ws.send('{"type":"pause"}')
        await ws.send('{"type":"seek","time":2.0}')
        # asked each second, as the page does (the protocol's rule)
        deadline, asked = time.monotonic() + 30, 0.0
        while time.monotonic() < deadline:
            if time.monotonic() - asked >= 1.0:
                asked = time.monotonic()
                await ws.send('{"type":"select","body":1}')
            message = await asyncio.wait_for(ws.recv(), 10)
            if not isinstance(message, bytes):
                continue
            magic, n, t, rate, late, sample = struct.unpack_from("<IIdfIQ", message)
            at = 32 + 28 * n
            (length,) = struct.unpack_from("<I", message, at)
            trailer = json.loads(message[at + 4:at + 4 + length])
            for d in trailer.get("details") or []:
                if d["body"] == 1 and abs(t - 2.0) < 1e-9:
                    return t, d
    return None, None


replayed = ViewedRun(ssx, None, None, replay=str(detailed))
try:
    t, d = asyncio.run(details_of(replayed.url))
finally:
    replayed.stop()
if d is None:
    problems.append("a robot selected in the replay: no details came with the frames at 2 s")
else:
    kinds = [m["kind"] for m in d["sensors"]]
    print(f"replayed q1's details at {t:.3f} s: command {d['command']}, sensors {kinds}, v {d['v']}")
    if d["name"] != "q1" or not d["command"] or "imu" not in kinds or len(d["v"]) != 3 or len(d["w"]) != 3:
        problems.append(f"the replay's details of q1: {d}")
    if ssx_module:
        r = ssx_module.Recording(str(detailed))
        commands = [m for at_s, m in r.channel("/ssx/commands") if at_s <= 2.0 + 1e-9]
        sensors = [m for at_s, m in r.channel("/ssx/sensors") if at_s <= 2.0 + 1e-9]
        if d["command"] != commands[-1]["q1"]:
            problems.append(f"the replay's command of q1 {d['command']}, the recording's {commands[-1]['q1']}")
        imu = next(m for m in d["sensors"] if m["kind"] == "imu")
        recorded_imu = next(m for m in sensors[-1]["q1"].values() if m["kind"] == "imu")
        if imu["accelerometer"] != recorded_imu["accelerometer"]:
            problems.append(f"the replay's IMU of q1 {imu}, the recording's {recorded_imu}")


def panel_in_browser():
    from viewer_util import chromium_available, headless_chromium, wait_until
    try:
        import selenium  # noqa: F401
    except ImportError:
        return print("selenium is not installed: the replay's panel in a browser not tried")
    if not chromium_available():
        return print("chromium is not installed: the replay's panel in a browser not tried")
    page = headless_chromium(work / "profile_panel")
    played = ViewedRun(ssx, None, None, replay=str(detailed))
    try:
        page.get(played.url)
        wait_until(page, "return document.getElementById('robots').textContent", lambda v: v == "3", problems)
        page.execute_script("window.ssxViewer.select(1)")
        text = wait_until(page, "return document.getElementById('selected').textContent",
                          lambda v: "command (" in v and "imu: accelerometer" in v, problems, 20)
        page.save_screenshot(str(work / "replay_panel.png"))
        print("the replay's panel of q1:\n  " + text.replace("\n", "\n  "))
        if "command (" not in text or "imu: accelerometer" not in text or "angular velocity" not in text:
            problems.append(f"the replay's panel of q1 lacks its command, IMU or velocities: {text!r}")
    finally:
        page.quit()
        played.stop()


panel_in_browser()
print("\n".join(problems) if problems else "the recording played on the page as recorded, at its speed, paused, "
      "stepped and sought; a robot's details as recorded")
sys.exit(1 if problems else 0)
