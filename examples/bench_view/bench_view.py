#!/usr/bin/env python3
"""What watching costs: N quadrotors of the real-time study (tau = 20 ms, 2 threads) fly into a
formation in real time with `ssx run`, alternately without the viewer and with it and PAGES pages
(python3-websockets clients asking for 30 frames a second and reading every one), RUNS times each.
Prints per run the median and p99 step time and the late steps (the run's own summary) and the
frames each page got:
    n=N run=K view=0|1 median_ms=... p99_ms=... late=... frames_per_page=...
then, with Debian's chromium, chromium-driver and python3-selenium installed, the page's own frame
rate drawing N robots in headless Chromium (WebGL through SwiftShader, on the same two cores as the
run):
    n=N page_fps_median=... page_fps_min=... (samples over S s)
With --foxglove the watchers are Foxglove clients instead (`ssx run --foxglove`; python3-websockets
clients of its protocol subscribed to /tf, /scene, /ssx/timing, /ssx/sensors, /ssx/commands and
/ssx/run, reading every message): frames_per_page is then the /tf messages each got, and
snapshot_ms_mean / snapshot_ms_max what a snapshot for them took the stepping thread (the run's
closing line).

With --channels LIST they subscribe to those topics only (frames_per_page: messages of the first).

    bench_view.py SSX [--n N]... [--seconds S] [--runs R] [--pages K] [--fps-seconds S] [--foxglove [--channels LIST]]"""
import argparse
import asyncio
import math
import pathlib
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import time

here = pathlib.Path(__file__).resolve().parent
artifact = here.parent / "artifacts" / "mk_quad_formation.xml"


def scene_text(n):
    """The real-time study's formation (as ssx_bench_record has it): takes off at 2 s into a sphere."""
    radius = max(1.5, 4.0 * math.sqrt(n / 70.0))
    half = max(3.0, 1.6 * radius)
    return (f'<scene><environment timestep="0.02" seed="5" threads="2"/><type name="q" file="{artifact}"/><ground/>'
            f'<swarm type="q" count="{n}" name="quad{{i}}" layout="random" min="{-half:.3f} {-half:.3f} 0.05" '
            f'max="{half:.3f} {half:.3f} 0.05" min_distance="1.0"><driver formation_index="{{i}}" formation_size="{n}" '
            f'formation_radius="{radius:.3f}" formation_center="0 0 {radius + 1.5:.3f}" inner_rate_hz="50" '
            f'outer_rate_hz="50" offset="0 0 1.5" start_time="2"/></swarm></scene>')


def start(ssx, scene, out, seconds, view, foxglove=False):
    args = [ssx, "run", str(scene), "--realtime", "--duration", str(seconds), "--out", str(out)]
    if view:
        args += ["--foxglove", "0"] if foxglove else ["--view", "0"]
    process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    url, lines = None, []
    while view and url is None:
        line = process.stderr.readline()
        if not line:
            sys.exit("ssx ended before the viewer listened:\n" + "".join(lines))
        lines.append(line)
        found = re.search(r"(?:viewer|foxglove): ((?:http|ws)://\S+)", line)
        url = found.group(1) if found else None
    return process, url, lines


def summary(text):
    median = re.search(r"step time ms[^:]*: median ([\d.]+)\s+p95 [\d.]+\s+p99 ([\d.]+)", text)
    late = re.search(r"overruns (\d+)", text)
    if not median or not late:
        sys.exit("no timing summary in the run's output:\n" + text[-3000:])
    return float(median.group(1)), float(median.group(2)), int(late.group(1))


async def until_the_end(process, watchers):
    """Runs the watchers (coroutines) until the run ends, then stops them."""
    tasks = [asyncio.create_task(w) for w in watchers]
    while process.poll() is None:
        await asyncio.sleep(0.2)
    for t in tasks:
        t.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)


async def pages(url, count, process):
    """`count` pages at 30 frames a second, reading every frame until the run ends; frames each got."""
    import websockets
    ws_url = url.replace("http://", "ws://").rstrip("/") + "/ws"
    got = [0] * count

    async def page(k):
        try:
            async with websockets.connect(ws_url, max_size=None) as ws:
                await ws.send('{"type":"hello","rate_hz":30}')
                async for message in ws:
                    if isinstance(message, bytes):
                        got[k] += 1
        except (websockets.exceptions.ConnectionClosed, OSError):
            pass
    await until_the_end(process, [page(k) for k in range(count)])
    return got


FIXED = ["/tf", "/scene", "/ssx/timing", "/ssx/sensors", "/ssx/commands", "/ssx/run"]  # the swarm's channels


async def foxglove_clients(url, count, process, topics=None):
    """`count` Foxglove clients subscribed to `topics` (None: the run's fixed channels), reading every
    message until the run ends; the messages each got of the first of them (/tf when all)."""
    import json
    import websockets
    got = [0] * count

    async def client(k):
        counted = None
        try:
            async with websockets.connect(url, subprotocols=["foxglove.websocket.v1"], max_size=None) as ws:
                async for message in ws:
                    if isinstance(message, str) and json.loads(message).get("op") == "advertise":
                        channels = json.loads(message)["channels"]
                        wanted = [c for t in (topics or FIXED) for c in channels if c["topic"] == t]
                        if len(wanted) != len(topics or FIXED):
                            sys.exit(f"--channels {','.join(topics or FIXED)}: the run offers "
                                     f"{', '.join(c['topic'] for c in channels[:20])}, ...")
                        counted = wanted[0]["id"]
                        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [
                            {"id": c["id"], "channelId": c["id"]} for c in wanted]}))
                    elif isinstance(message, bytes) and message[0] == 1 and int.from_bytes(message[1:5], "little") == counted:
                        got[k] += 1
        except (websockets.exceptions.ConnectionClosed, OSError):
            pass
    await until_the_end(process, [client(k) for k in range(count)])
    return got


def page_fps(ssx, scene, out, seconds):
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.options import Options
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        return None
    if not pathlib.Path("/usr/bin/chromedriver").exists():
        return None
    process, url, _ = start(ssx, scene, out, seconds + 60, True)
    options = Options()
    for a in ("--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
              "--window-size=1024,700"):
        options.add_argument(a)
    browser = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    samples = []
    try:
        browser.get(url)
        deadline = time.monotonic() + 60
        while browser.execute_script("return window.ssxViewer.state.frames") < 10 and time.monotonic() < deadline:
            time.sleep(0.5)
        time.sleep(2)  # the page's counter is per second
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            time.sleep(1.0)
            samples.append(float(browser.execute_script("return document.getElementById('fps').textContent")))
    finally:
        browser.quit()
        process.send_signal(signal.SIGINT)
        process.communicate(timeout=120)
    return samples


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("ssx")
    parser.add_argument("--n", type=int, action="append")
    parser.add_argument("--seconds", type=float, default=20)
    parser.add_argument("--runs", type=int, default=2)
    parser.add_argument("--pages", type=int, default=2)
    parser.add_argument("--fps-seconds", type=float, default=10)
    parser.add_argument("--foxglove", action="store_true", help="Foxglove clients instead of the viewer's pages")
    parser.add_argument("--channels", help="with --foxglove: the topics the clients subscribe to, comma-separated "
                        "(default: /tf, /scene, /ssx/timing, /ssx/sensors, /ssx/commands, /ssx/run)")
    a = parser.parse_args()
    with tempfile.TemporaryDirectory() as work:
        work = pathlib.Path(work)
        for n in a.n or [1000, 10000]:
            scene = work / f"formation{n}.xml"
            scene.write_text(scene_text(n))
            medians = {0: [], 1: []}
            for run in range(2 * a.runs):
                view = run % 2
                process, url, lines = start(a.ssx, scene, work / f"out{n}_{run}", a.seconds, view, a.foxglove)
                topics = a.channels.split(",") if a.channels else None
                got = []
                if view:
                    watched = foxglove_clients(url, a.pages, process, topics) if a.foxglove else pages(url, a.pages, process)
                    got = asyncio.run(watched)
                out, err = process.communicate()
                median, p99, late = summary(out + "".join(lines) + err)
                medians[view].append(median)
                # the Foxglove extension's closing line: what a snapshot cost the stepping thread
                taken = re.search(r"a snapshot took ([\d.]+) ms on the stepping thread on average, ([\d.]+) ms at most", err)
                print(f"n={n} run={run // 2} view={view} median_ms={median:.3f} p99_ms={p99:.3f} late={late} "
                      f"frames_per_page={'/'.join(map(str, got)) if got else '-'}"
                      + (f" snapshot_ms_mean={taken.group(1)} snapshot_ms_max={taken.group(2)}" if taken else ""), flush=True)
            print(f"n={n} median_ms without {statistics.median(medians[0]):.3f} with {statistics.median(medians[1]):.3f} "
                  f"({100 * (statistics.median(medians[1]) / statistics.median(medians[0]) - 1):+.1f} %)", flush=True)
            samples = page_fps(a.ssx, scene, work / f"fps{n}", a.fps_seconds) if a.fps_seconds > 0 and not a.foxglove else None
            if samples:
                print(f"n={n} page_fps_median={statistics.median(samples):.0f} page_fps_min={min(samples):.0f} "
                      f"(samples over {a.fps_seconds:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
