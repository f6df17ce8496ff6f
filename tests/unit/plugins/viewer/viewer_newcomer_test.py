#!/usr/bin/env python3
"""What a newcomer to the viewer expects, in a real browser (headless Chromium, as viewer_test.py):

    viewer_newcomer_test.py SSX SCENE WORK_DIR [SCREENSHOT]

The formation runs in real time with --view-wait for 8 simulated seconds:
- the run holds after its first step until a page connects (it says so; the page's first frames
  are from the start, though it connected seconds later);
- the ground has its grid; a robot found by name in the list is selected and followed: a ring
  around it, its name on a label where it is drawn, and the plots of its height and speed and of its
  sensors (IMU, range) drawing;
- the camera cannot be put under the ground, and "reset view" brings back the first view;
- in a narrow window (600 px) the panel fits in it;
- when the run ends the page keeps its last frame and says how the run ended.
Exits 77 (ctest: skipped) when Chromium, its driver or selenium is not installed."""
import pathlib
import re
import shutil
import subprocess
import sys
import time

from viewer_util import chromium_available, headless_chromium, wait_until

try:
    import selenium  # noqa: F401
except ImportError:
    print("selenium is not installed (apt-get install python3-selenium): skipped")
    sys.exit(77)
if not chromium_available():
    print("chromium or chromedriver is not installed (apt-get install chromium chromium-driver): skipped")
    sys.exit(77)

ssx, scene, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
screenshot = sys.argv[4] if len(sys.argv) > 4 else None
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
problems = []

run = subprocess.Popen([ssx, "run", scene, "--realtime", "--view", "0", "--view-wait", "--duration", "8", "--out",
                        str(work / "out")], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
lines, url = [], None
deadline = time.monotonic() + 60
while time.monotonic() < deadline:
    line = run.stderr.readline()
    if not line:
        break
    lines.append(line)
    m = re.search(r"viewer: the run waits for a page at (http://\S+)", line)
    if m:
        url = m.group(1)
        break
if url is None:
    run.kill()
    sys.exit("the run never said it waits for a page:\n" + "".join(lines))
time.sleep(2.0)  # (a run that did not wait would be 2 s on by now)
page = headless_chromium(f"{work}/profile")
try:
    asked = time.monotonic()
    page.get(url)
    wait_until(page, "return document.getElementById('robots').textContent", lambda v: v == "70", problems)
    first = wait_until(page, "return window.ssxViewer.state.time", lambda v: v is not None and v > 0, problems)
    # (simulated time, at most real time, since the page came: a run that had not waited would be 2 s on)
    if not first or first > time.monotonic() - asked + 1.0:
        problems.append(f"the page's first frame is at t = {first} s, {time.monotonic() - asked:.1f} s after it "
                        f"connected: the run did not wait for it")
    wait_until(page, "return window.ssxViewer.state.time", lambda v: v is not None and v > 1.5, problems)

    # the ground's grid: drawn, lines both ways (seen from above, away from the robots: a point on a
    # line along x and one on a line along y are darker than the middle of a cell)
    grids = page.execute_script("return window.ssxViewer.scene.children.filter((c) => c.userData.grid).length")
    shades = page.execute_script("""const v = window.ssxViewer;
      v.controls.target.set(20, 20, 0); v.camera.position.set(20.01, 16, 6); v.controls.update(); v.draw();
      const at = (x, y) => { const p = new THREE.Vector3(x, y, 0).project(v.camera);
        return [((p.x + 1) / 2) * window.innerWidth, ((1 - p.y) / 2) * window.innerHeight]; };
      const darkest = (x, y) => { const [u, w] = at(x, y); let low = 255;
        for (let i = -1; i <= 1; ++i) for (let j = -1; j <= 1; ++j) low = Math.min(low, v.pixel(u + i, w + j)[1]); return low; };
      return [darkest(20.5, 20), darkest(20, 20.5), v.pixel(...at(20.5, 20.5))[1]];""")
    if grids < 1 or not (shades[0] < shades[2] - 10 and shades[1] < shades[2] - 10):
        problems.append(f"no grid on the ground both ways: {grids} grids, green on a line along x {shades[0]}, "
                        f"along y {shades[1]}, in a cell {shades[2]}")
    # soft shadows (70 robots: on by default): seen from above, the ground where pillar0 (at 6.5 0,
    # 6 m tall) casts its shadow at 3 m up (the sun along 0.35 0.25 0.9: 1.17 m and 0.83 m back) is
    # darker than when the same picture is drawn without shadows
    shade = page.execute_script("""const v = window.ssxViewer;
      v.controls.target.set(5.33, -0.83, 0); v.camera.position.set(5.34, -0.9, 8); v.controls.update();
      const at = (x, y) => { const p = new THREE.Vector3(x, y, 0).project(v.camera);
        return [((p.x + 1) / 2) * window.innerWidth, ((1 - p.y) / 2) * window.innerHeight]; };
      const on = v.state.shadows; v.draw(); const lit = v.pixel(...at(5.33, -0.83))[1];
      v.shadows(false); v.draw(); const plain = v.pixel(...at(5.33, -0.83))[1];
      v.shadows(true); return [on, lit, plain];""")
    print(f"pillar0's shadow on the ground: green {shade[1]} with shadows, {shade[2]} without")
    if not shade[0] or not shade[1] < shade[2] - 15:
        problems.append(f"no shadow of pillar0 on the ground: shadows on {shade[0]}, green {shade[1]} with them, "
                        f"{shade[2]} without")
    page.execute_script("document.getElementById('reset').click()")

    # a robot by name: selected, followed, ringed, labelled, plotted
    page.execute_script("const f = document.getElementById('find'); f.value = 'quad5';"
                        "f.dispatchEvent(new Event('change'));")
    index = page.execute_script("return window.ssxViewer.state.bodies.findIndex((b) => b.name === 'quad5')")
    selected = page.execute_script("return window.ssxViewer.state.selected")
    follow = page.execute_script("return document.getElementById('follow').checked")
    if selected != index or not follow:
        problems.append(f"found by name: selected {selected} (quad5 is {index}), following {follow}")
    time.sleep(2.0)
    ring = page.execute_script("const r = window.ssxViewer.ring, p = window.ssxViewer.state.positions, i = window.ssxViewer.state.selected;"
                               "return [r.visible, Math.hypot(r.position.x - p[7*i], r.position.y - p[7*i+1], r.position.z - p[7*i+2])]")
    if not ring[0] or ring[1] > 0.5:
        problems.append(f"the selected robot's ring: visible {ring[0]}, {ring[1]:.2f} m from it")
    label = page.execute_script("const l = document.getElementById('pick'), r = l.getBoundingClientRect();"
                                "const at = window.ssxViewer.project(window.ssxViewer.state.selected);"
                                "return [l.hidden, l.textContent, r.left + r.width / 2, r.bottom, at]")
    if label[0] or label[1] != "quad5" or label[4] is None or abs(label[2] - label[4][0]) > 30 or not 0 < label[4][1] - label[3] < 80:
        problems.append(f"the selected robot's label: {label}")
    plotted = page.execute_script("return window.ssxViewer.state.plotted || 0")
    lit = page.execute_script("const c = document.getElementById('plot'), d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
                              "let n = 0; for (let k = 3; k < d.length; k += 4) n += d[k] > 0; return n")
    if plotted < 10 or lit < 200:
        problems.append(f"the plot: {plotted} samples, {lit} pixels drawn")
    # its sensors' plot (an IMU and a range sensor: |accel|, |gyro|, the nearest robot), below it
    sensed = "const c = document.getElementById('sensor_plot'), d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;" \
             "let n = 0; for (let k = 3; k < d.length; k += 4) n += d[k] > 0; return [c.hidden, window.ssxViewer.state.sensorPlotted || 0, n]"
    sensors = wait_until(page, sensed, lambda v: not v[0] and v[1] >= 5 and v[2] >= 150, problems, 30)
    print(f"the sensors' plot: hidden {sensors[0]}, {sensors[1]} samples, {sensors[2]} pixels drawn")
    if screenshot:
        page.save_screenshot(screenshot)

    # the camera under the ground: held above it; reset view: the first view again
    page.execute_script("document.getElementById('follow').checked = false;")
    start = page.execute_script("document.getElementById('reset').click(); const c = window.ssxViewer.camera.position; return [c.x, c.y, c.z]")
    below = page.execute_script("const v = window.ssxViewer, c = v.camera.position; c.set(v.controls.target.x + 3, v.controls.target.y, -4);"
                                "v.controls.update(); return [c.z, v.controls.target.z]")
    if below[0] < below[1] - 0.2 or below[0] < 0:
        problems.append(f"the camera went under the ground: z = {below[0]:.2f} (target {below[1]:.2f})")
    again = page.execute_script("document.getElementById('reset').click(); const c = window.ssxViewer.camera.position; return [c.x, c.y, c.z]")
    if max(abs(a - b) for a, b in zip(start, again)) > 3.0:
        problems.append(f"reset view: {again}, the first view was {start}")

    # a narrow window: the panel inside it
    page.set_window_size(600, 700)
    time.sleep(0.5)
    box = page.execute_script("const r = document.getElementById('panel').getBoundingClientRect();"
                              "return [r.left, r.right, r.top, r.bottom, window.innerWidth, window.innerHeight]")
    if box[0] < 0 or box[1] > box[4] or box[2] < 0 or box[3] > box[5]:
        problems.append(f"the panel does not fit a 600 px window: {box}")

    # the end: the last frame stays, and what the run said
    status = wait_until(page, "return document.getElementById('status').textContent", lambda v: "ended" in v, problems, 60)
    if not re.search(r"the run ended: t = 8\.000 s after 4000 steps, \d+ of them late", status or ""):
        problems.append(f"at the end the page says {status!r}")
    if not page.execute_script("return window.ssxViewer.state.positions !== null && window.ssxViewer.state.ended"):
        problems.append("at the end the page dropped its last frame")
finally:
    page.quit()
    out, err = run.communicate(timeout=60)
if run.returncode != 0:
    problems.append(f"ssx ended with status {run.returncode}:\n{''.join(lines) + err}"[-2000:])
print("\n".join(problems) if problems else "the viewer waited, found, ringed, labelled, plotted, kept above the ground and ended well")
sys.exit(1 if problems else 0)
