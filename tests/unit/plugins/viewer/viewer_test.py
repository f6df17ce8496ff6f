#!/usr/bin/env python3
"""The viewer in a real browser: the formation runs in real time with --view; headless Chromium
(Debian's chromium and chromium-driver, driven by selenium; WebGL through SwiftShader) opens the
page. Passes when the page shows every robot and the simulated time advancing, draws each robot
where the simulation has it (the robot's blue at the projected centre of most robots in view, and
mostly not a little beside them), a robot selected shows its velocities, command and sensors in
the panel, and steered with the W key (forward along the view) for 2 s it moves forward in the
simulation (the panel showing the velocity commanded and achieved, how long a command waited for
its step and how long from the key to the picture of that step) and stops when the key is let
go, with "steer every robot" the W key moves the whole formation, the page's pause
holds the run (the time shown stands still), its step button takes a step and holds again, its resume and
real-time factor 4 reach the run (its frames say so, and it goes no faster than 4 times the wall
clock), and a second page sees the same run.

    browser_test.py SSX SCENE WORK_DIR [SCREENSHOT]

Exits 77 (ctest: skipped) when Chromium, its driver or selenium is not installed."""
import pathlib
import re
import shutil
import sys
import time

from viewer_util import ViewedRun, chromium_available, headless_chromium, wait_until

try:
    from selenium.webdriver.common.action_chains import ActionChains
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


def browser():
    return headless_chromium(f"{work}/profile{len(pages)}")


def wait_for(page, what, condition, seconds=60):
    return wait_until(page, what, condition, problems, seconds)


pages = []
run = ViewedRun(ssx, scene, str(work / "out"), "--duration", "120")
try:
    page = browser()
    pages.append(page)
    page.get(run.url)
    robots = wait_for(page, "return document.getElementById('robots').textContent", lambda v: v == "70")
    t0 = float(wait_for(page, "return document.getElementById('time').textContent",
                        lambda v: v not in ("-", "") and float(v) > 1.0))
    time.sleep(1.0)
    t1 = float(page.execute_script("return document.getElementById('time').textContent"))
    if not t1 > t0:
        problems.append(f"the displayed time did not advance: {t0} then {t1}")
    # each robot where the simulation has it: its blue box at its projected centre
    result = page.execute_script("""
        const v = window.ssxViewer, n = v.state.bodies.length;
        v.draw();  // the picture read below, of the poses project() uses
        let seen = 0, blue = 0, beside = 0;
        const isBlue = (c) => c[2] > c[0] + 40 && c[2] > c[1] + 20;
        for (let i = 0; i < n; ++i) {
          const at = v.project(i);
          if (!at || at[0] < 20 || at[1] < 60 || at[0] > innerWidth - 20 || at[1] > innerHeight - 20) continue;
          ++seen;
          let hit = false;
          for (const [dx, dy] of [[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1]]) hit = hit || isBlue(v.pixel(at[0] + dx, at[1] + dy));
          if (hit) ++blue;
          if (isBlue(v.pixel(at[0] + 40, at[1] + 40))) ++beside;
        }
        return [seen, blue, beside];""")
    seen, blue, beside = result
    print(f"robots in view {seen}, robot colour at their centre {blue}, 40 px beside them {beside}")
    if seen < 30:
        problems.append(f"only {seen} of 70 robots in view")
    if blue < 0.8 * seen:
        problems.append(f"the robot's colour at only {blue} of {seen} robots' projected centres")
    if beside > 0.3 * seen:
        problems.append(f"the robot's colour 40 px beside {beside} of {seen} robots: not drawn where they are")
    if screenshot:
        page.save_screenshot(screenshot)
    # steer robot 0 forward along the view for 2 s with the W key, then let go
    where = """const v = window.ssxViewer, p = v.state.positions;
               const look = [v.controls.target.x - v.camera.position.x, v.controls.target.y - v.camera.position.y];
               const n = Math.hypot(look[0], look[1]);
               return [p[0], p[1], p[2], look[0] / n, look[1] / n, v.state.time];"""
    page.execute_script("window.ssxViewer.select(0)")
    # its details from the simulation in the panel: velocities, the current command, every sensor
    panel = "return document.getElementById('selected').textContent"
    text = wait_for(page, panel, lambda v: "angular velocity" in v and "range: " in v, 20)
    print("the panel of robot 0:\n  " + text.replace("\n", "\n  "))
    for expected in ("quad0", "command (position)", "imu: accelerometer", "pose: position", " in range"):
        if expected not in text:
            problems.append(f"the panel of robot 0 lacks {expected!r}: {text!r}")

    def wait_simulated(seconds):
        """Waits until the page shows `seconds` more of simulated time (the run may be slower than real time
        on a loaded machine); returns the robot's pose then."""
        start = page.execute_script(where)[5]
        return wait_for(page, where, lambda w: w[5] >= start + seconds, 120)

    before = page.execute_script(where)
    ActionChains(page).key_down("w").perform()
    # held for 2 s of simulated time and until the robot went 1 m (a page starved of the CPU on a loaded
    # machine may send nothing for a while, and the viewer rightly stops robots 0.5 s after the last message)
    wait_simulated(2.0)
    during = wait_for(page, where, lambda w: (w[0] - before[0]) * before[3] + (w[1] - before[1]) * before[4] >= 1.0, 120)
    steering = page.execute_script(panel)
    ActionChains(page).key_up("w").perform()
    if "command (velocity)" not in steering or "commanded " not in steering or "achieved " not in steering:
        problems.append(f"steering, the panel does not show the velocity commanded and achieved: {steering!r}")
    latency = re.search(r"steering: ([\d.]+) ms from a command's arrival to its step,\s+(\d+) ms from the key to the "
                        r"picture of that step", steering)
    if not latency:
        problems.append(f"steering, the panel does not show a command's delays: {steering!r}")
    else:
        print(f"the panel while steering: {latency.group(1)} ms from arrival to step, {latency.group(2)} ms from the key "
              f"to the picture")
    settled = wait_simulated(2.0)  # the velocity level's reference point stops at once; the robot settles on it
    still = wait_simulated(1.0)
    held = during[5] - before[5]
    forward = (during[0] - before[0]) * before[3] + (during[1] - before[1]) * before[4]
    drift = sum((still[k] - settled[k]) ** 2 for k in range(3)) ** 0.5
    print(f"robot 0 moved {forward:.2f} m forward in {held:.2f} s of the key held (1 m/s asked); "
          f"{drift:.3f} m in the {still[5] - settled[5]:.2f} s from 2 s after it was let go")
    if forward < 1.0:
        problems.append(f"steered forward at 1 m/s for {held:.2f} s, robot 0 moved {forward:.2f} m along the view")
    if drift > 0.05:
        problems.append(f"robot 0 still moved {drift:.3f} m in a second, 2 s after the key was let go")
    # the whole formation: every robot forward along the view at once. The key is held until every robot
    # has gone 0.7 m (not for a fixed time: a page starved of the CPU on a loaded machine sends nothing
    # for a while, and the viewer rightly stops robots 0.5 s after a page's last message). A robot the
    # command missed would not move: the wait fails after 120 s
    everyone = "return [Array.from(window.ssxViewer.state.positions), window.ssxViewer.state.time]"

    def along_view(now, then):
        return [(now[0][7 * i] - then[0][7 * i]) * before[3] + (now[0][7 * i + 1] - then[0][7 * i + 1]) * before[4]
                for i in range(70)]

    page.find_element("id", "steer_all").click()
    start = page.execute_script(everyone)
    ActionChains(page).key_down("w").perform()
    reached = wait_for(page, everyone, lambda now: min(along_view(now, start)) >= 0.7, 120)
    ActionChains(page).key_up("w").perform()
    wait_simulated(1.5)
    end = page.execute_script(everyone)
    page.find_element("id", "steer_all").click()
    # (where they are 1.5 s after the key is let go is printed, not asserted: in a loaded CI run one robot
    # was then 0.60 m along, back from the 0.7 m every robot had reached while the key was held)
    moved, after = along_view(reached, start), along_view(end, start)
    print(f"the formation steered forward: every robot 0.7 m along the view after {reached[1] - start[1]:.2f} s "
          f"of simulated time (1 m/s asked): {min(moved):.2f} to {max(moved):.2f} m; 1.5 s after the key was let go "
          f"{min(after):.2f} to {max(after):.2f} m")
    # pause, one step, then on at four times real time, all from the page
    shown = "return Number(document.getElementById('time').textContent)"
    page.find_element("id", "pause").click()
    time.sleep(0.5)
    held = page.execute_script(shown)
    time.sleep(0.7)
    if page.execute_script(shown) != held:
        problems.append(f"paused from the page, the time shown went on from {held}")
    page.find_element("id", "step").click()
    stepped = wait_for(page, shown, lambda v: v != held, 10)
    # (the frame shown before may be a few steps older than the pause, if the pause came while the
    # run waited for a deadline: C++'s run-loop test checks single steps exactly)
    if not 0.0015 < stepped - held < 0.05:
        problems.append(f"one step from the page went from {held} to {stepped} s (one step is 0.002 s)")
    time.sleep(0.5)
    if page.execute_script(shown) != stepped:
        problems.append("after one step from the page the run did not hold again")
    from selenium.webdriver.support.ui import Select
    Select(page.find_element("id", "factor")).select_by_visible_text("4")
    page.find_element("id", "pause").click()  # resume
    # the run has the factor (its frames say so; C++'s run-loop test checks the pacing it gives)
    asked = wait_for(page, "return document.getElementById('asked').textContent", lambda v: "4" in v, 10)
    t_a, wall_a = page.execute_script(shown), time.monotonic()
    time.sleep(3.0)
    t_b, wall_b = page.execute_script(shown), time.monotonic()
    factor = (t_b - t_a) / (wall_b - wall_a)
    print(f"paused at {held:.3f} s, one step to {stepped:.3f} s, then x{factor:.2f} real time with 4 asked "
          f"(the page says{asked})")
    # how near 4 a run gets depends on the machine's load (x2.13 in one CI run beside Chromium's
    # drawing and other tests, x1.17 beside a build): printed; more than 4 would be the pacing broken
    if "4" not in asked or factor > 4.5:
        problems.append(f"asked for 4 times real time from the page, the run went x{factor:.2f}; the page says {asked!r}")
    # a second page sees the same run
    second = browser()
    pages.append(second)
    second.get(run.url)
    wait_for(second, "return document.getElementById('robots').textContent", lambda v: v == "70")
    t2 = float(wait_for(second, "return document.getElementById('time').textContent",
                        lambda v: v not in ("-", "") and float(v) > t1))
    print(f"first page at {t1:.3f} s, second page at {t2:.3f} s")
finally:
    for p in pages:
        p.quit()
    status, err = run.stop()
if status != 130:
    problems.append(f"ssx ended with status {status} after Ctrl-C (130 expected):\n{err[-2000:]}")
if "viewer: " not in err or " frames published" not in err:
    problems.append(f"no viewer summary at the end:\n{err[-2000:]}")
delays = re.search(r"viewer: (\d+) velocity commands from pages, from arrival to the step that used them median "
                   r"([\d.]+) ms, max ([\d.]+) ms", err)
if not delays:
    problems.append(f"no account of the velocity commands:\n{err[-2000:]}")
else:
    print(f"{delays.group(1)} velocity commands, from arrival to the step that used them: median {delays.group(2)} ms, "
          f"max {delays.group(3)} ms")
print("\n".join(problems) if problems else "the page drew the run as the simulation had it, on two pages")
sys.exit(1 if problems else 0)
