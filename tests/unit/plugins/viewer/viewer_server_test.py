#!/usr/bin/env python3
"""The viewer's protocol against hostile and slow pages (python3-websockets), on loopback.

    viewer_server_test.py SSX EXAMPLES_DIR WORK_DIR [ROBOTS]

ROBOTS (default 3,000) is fewer in the sanitized builds, whose ssx is slower than real time with
3,000.

A swarm of 3,000 light robots (84 KB a frame) runs in real time with --view; then:
- a page gets the scene (JSON: every body) and binary frames of every body in the documented
  layout, their times rising; after selecting a robot its frames carry that robot's details (name,
  velocities, command, sensors); a page asking for 5 frames a second gets no more;
- malformed, oversized, binary and too many messages are dropped and counted, and the page stays
  connected and served;
- a page beyond max_clients (4) is refused; the viewer serves only its own files (no path
  traversal, 404);
- a page that connects and never reads holds nothing up: the others keep getting frames, and the
  run keeps real time no worse than without it (late steps counted by the run itself);
- the counts in the viewer's summary at the end say all of it;
- a second run asking for the same port is refused before it starts (status 2, nothing made);
- on another address (127.0.0.2, still loopback) the page and its socket need the printed token.
Exits 77 when python3-websockets is not installed."""
import asyncio
import json
import pathlib
import re
import shutil
import socket
import struct
import subprocess
import sys
import urllib.error
import urllib.request

from viewer_util import ViewedRun

try:
    import websockets
except ImportError:
    print("python3-websockets is not installed: skipped")
    sys.exit(77)

ssx, examples, work = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
ROBOTS = int(sys.argv[4]) if len(sys.argv) > 4 else 3000
scene = work / "swarm.xml"
scene.write_text(f"""<scene><environment timestep="0.01" seed="1" threads="2"/>
  <type name="r" file="{examples / 'artifacts' / 'hover_body.xml'}"/><ground/>
  <swarm type="r" count="{ROBOTS}" name="r{{i}}" layout="grid" spacing="1.0" xyz="-27 -27 0.05"/></scene>""")
problems = []


async def scene_and_frames(ws, frames=3, description=None):
    """Reads until a scene with bodies (unless given), then `frames` frames; returns (scene, [(time, n, step,
    details)])."""
    out = []
    while len(out) < frames:
        message = await asyncio.wait_for(ws.recv(), 10)
        if isinstance(message, str):
            description = json.loads(message)
            continue
        if description is None or not description["bodies"]:
            continue
        magic, n, t, rtf, late, step = struct.unpack_from("<IIdfIQ", message)
        length = struct.unpack_from("<I", message, 32 + 28 * n)[0] if len(message) >= 36 + 28 * n else -1
        if magic != 0x46585353 or len(message) != 36 + 28 * n + length:
            problems.append(f"a frame of {len(message)} bytes, magic {magic:#x}, {n} bodies, details {length}")
            length = 0
        trailer = json.loads(message[36 + 28 * n:].decode()) if length > 0 else {}
        if "run" not in trailer or set(trailer["run"]) != {"factor", "paused"}:
            problems.append(f"a frame without the run's pace: {trailer}")
        details = trailer.get("details", [])
        out.append((t, n, step, details))
    return description, out


async def main(url):
    ws_url = url.replace("http://", "ws://").rstrip("/") + "/ws"
    async with websockets.connect(ws_url, max_size=None) as page:
        description, frames = await scene_and_frames(page)
        n = len(description["bodies"])
        if n != ROBOTS or any(f[1] != n for f in frames):
            problems.append(f"scene of {n} bodies, frames of {[f[1] for f in frames]}")
        if not all(a[0] < b[0] for a, b in zip(frames, frames[1:])):
            problems.append(f"frame times do not rise: {frames}")
        # hostile messages: not JSON, too large, binary, and far too many
        await page.send("{not json")
        await page.send("x" * 10000)
        await page.send(b"\x00\x01binary")
        for bad in ('{"type":"velocity","body":99999,"v":[1,0,0],"yaw_rate":0}',
                    '{"type":"velocity","body":0,"v":[1,0],"yaw_rate":0}',
                    '{"type":"velocity","body":0,"v":[1e9,0,0],"yaw_rate":0}',
                    '{"type":"velocity","body":-1,"v":[1,0,0],"yaw_rate":0}',
                    '{"type":"select","body":99999}', '{"type":"hello","rate_hz":0}', '{"type":"hello","rate_hz":1e6}'):
            await page.send(bad)  # no such robot, too few values, too fast, no such robot (twice), rates out of range
        for _ in range(400):
            await page.send('{"type":"hello"}')
        _, later = await scene_and_frames(page, 3, description)
        if not later[-1][0] > frames[-1][0]:
            problems.append("the page stopped getting frames after its bad messages")
        # a robot selected: its details in the frames from then on (once the flood's second is over)
        await asyncio.sleep(1.1)
        await page.send('{"type":"select","body":5}')
        details = []
        for _ in range(120):  # (the frames queued before it first)
            details = [d for d in (await scene_and_frames(page, 1, description))[1][0][3] if d["body"] == 5]
            if details:
                break
        if not details or details[-1]["name"] != "r5" or len(details[-1]["v"]) != 3 or len(details[-1]["w"]) != 3 \
                or "command" not in details[-1] or "sensors" not in details[-1]:
            problems.append(f"robot 5 selected, its details in the next 120 frames: {details[-1:]}")
        # a page asking for 5 frames a second
        async with websockets.connect(ws_url, max_size=None) as slow:
            await slow.send('{"type":"hello","rate_hz":5}')
            await scene_and_frames(slow, 1)
            loop = asyncio.get_running_loop()
            start, count = loop.time(), 0
            while loop.time() - start < 2:
                await scene_and_frames(slow, 1, description)
                count += 1
            print(f"a page asking for 5 frames a second got {count} in {loop.time() - start:.2f} s")
            if count > 14:  # (5 a second for 2 s, and those sent before its hello arrived)
                problems.append(f"a page asking for 5 frames a second got {count} in 2 s")
        # more pages than allowed: 3 more are served, the 5th is refused
        others = [await websockets.connect(ws_url, max_size=None) for _ in range(3)]
        try:
            refused = False
            try:
                extra = await websockets.connect(ws_url, max_size=None)
                await asyncio.wait_for(extra.recv(), 5)
                await extra.close()
            except (websockets.exceptions.InvalidStatusCode, websockets.exceptions.ConnectionClosed,
                    websockets.exceptions.InvalidHandshake, asyncio.TimeoutError, OSError):
                refused = True
            if not refused:
                problems.append("a 5th page was served (max_clients is 4)")
        finally:
            for o in others:
                await o.close()
        # a page that never reads: the handshake by hand, then silence for 6 s
        host, port = re.search(r"http://([^:/]+):(\d+)", url).groups()
        stalled = socket.create_connection((host, int(port)))
        stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        stalled.sendall(f"GET /ws HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n".encode())
        # for 6 s of the wall clock this page reads on: its frames cover about 6 s of simulated time
        loop = asyncio.get_running_loop()
        start, times = loop.time(), []
        while loop.time() - start < 6:
            times.append((await scene_and_frames(page, 1, description))[1][0][0])
        print(f"with a stalled page connected: {len(times)} frames in 6 s, simulated {times[0]:.2f} to {times[-1]:.2f} s")
        if times[-1] - times[0] < 4.5 or len(times) < 60:
            problems.append(f"with a stalled page the others got {len(times)} frames, {times[0]:.2f} to {times[-1]:.2f} s, in 6 s")
        stalled.close()


run = ViewedRun(ssx, str(scene), str(work / "out"), "--duration", "60")
try:
    for path, expected in (("/", 200), ("/viewer.js", 200), ("/../../etc/passwd", 404), ("/%2e%2e/etc/passwd", 404),
                           ("/CMakeLists.txt", 404)):
        try:
            status = urllib.request.urlopen(run.url.rstrip("/") + path, timeout=10).status
        except urllib.error.HTTPError as e:
            status = e.code
        if status != expected:
            problems.append(f"GET {path}: {status}, {expected} expected")
    asyncio.run(main(run.url))
    # the same port again: refused before anything starts
    second = subprocess.run([ssx, "run", str(scene), "--view", str(run.port), "--duration", "1", "--out", str(work / "second")],
                            capture_output=True, text=True, timeout=60)
    if second.returncode != 2 or "cannot listen on 127.0.0.1:" + str(run.port) not in second.stderr:
        problems.append(f"a second run on port {run.port}: status {second.returncode}, {second.stderr[-500:]!r}")
    if (work / "second").exists():
        problems.append("the refused run made its output directory")
finally:
    status, err = run.stop()

# another address: the token printed at start is needed
guarded = ViewedRun(ssx, str(scene), str(work / "guarded"), "--duration", "60", "--view-bind", "127.0.0.2")
try:
    token = re.search(r"\?token=([0-9a-f]{32})", guarded.url)
    if not token:
        problems.append(f"no token in {guarded.url}")
    else:
        base = guarded.url.split("?")[0]
        for url, expected in ((base, 403), (base + "?token=" + "0" * 32, 403), (guarded.url, 200)):
            try:
                got = urllib.request.urlopen(url, timeout=10).status
            except urllib.error.HTTPError as e:
                got = e.code
            if got != expected:
                problems.append(f"GET {url}: {got}, {expected} expected")

        async def socket_needs_token():
            ws = base.replace("http://", "ws://").rstrip("/") + "/ws"
            try:
                async with websockets.connect(ws) as c:
                    await asyncio.wait_for(c.recv(), 5)
                problems.append("the socket served a page without the token")
            except (websockets.exceptions.InvalidStatusCode, websockets.exceptions.InvalidHandshake,
                    websockets.exceptions.ConnectionClosed, asyncio.TimeoutError, OSError):
                pass
            async with websockets.connect(ws + "?token=" + token.group(1), max_size=None) as c:
                await scene_and_frames(c, 1)
        asyncio.run(socket_needs_token())
finally:
    guarded.stop()
summary = re.search(r"viewer: (\d+) frames published, (\d+) sent, (\d+) skipped by slow pages, (\d+) messages dropped, "
                    r"(\d+) pages refused", err)
if not summary:
    problems.append(f"no viewer summary:\n{err[-3000:]}")
else:
    published, sent, skipped, dropped, refused = map(int, summary.groups())
    print(f"frames published {published}, sent {sent}, skipped {skipped}; messages dropped {dropped}; pages refused {refused}")
    # not JSON we know, too large, binary and 7 bad messages: 10; of the 400 hellos, those beyond 200 a second
    if dropped < 10 + 150:
        problems.append(f"{dropped} messages dropped: the bad ones and those beyond the rate were not all counted")
    if refused < 1:
        problems.append("no page counted as refused")
    if skipped < 1:
        problems.append("no frame counted as skipped (the stalled page)")
late = re.findall(r"\((\d+) overruns in all\)", err)
print(f"late steps reported by the run: {late[-1] if late else 0}")
print("\n".join(problems) if problems else "the viewer held against bad, too many and stalled pages")
sys.exit(1 if problems else 0)
