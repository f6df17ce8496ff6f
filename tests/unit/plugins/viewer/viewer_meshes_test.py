#!/usr/bin/env python3
"""The viewer draws a robot's meshes: each file's triangles sent once per page, shared by every shape
and swarm member that draws it (python3-websockets and Chromium with selenium, loopback).

    viewer_meshes_test.py SSX EXAMPLES_DIR WORK_DIR [SCREENSHOT.png]

The KUKA iiwa read from its URDF (eight links, each drawn by its OBJ mesh; its base bolted to the
world) runs in real time with --view: the page's scene lists each mesh once, with triangles that index its vertices, and each
link's shape names its mesh with the mesh's bounding box as its size; Bitcraze's Crazyflie (SDF,
COLLADA) draws its four propellers with two meshes (clockwise and counter-clockwise), each sent once.
In headless Chromium the page makes one geometry per mesh, three corners per triangle, and draws
the arm where its links are. Exits 77 without python3-websockets, selenium or Chromium."""
import asyncio
import json
import pathlib
import shutil
import sys

from viewer_util import ViewedRun, chromium_available, headless_chromium, wait_until

try:
    import selenium  # noqa: F401 - headless_chromium's
    import websockets
except ImportError:
    print("python3-websockets or python3-selenium is not installed: skipped")
    sys.exit(77)
if not chromium_available():
    print("chromium or chromium-driver is not installed: skipped")
    sys.exit(77)

ssx, examples, work = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
screenshot = sys.argv[4] if len(sys.argv) > 4 else None
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
problems = []


async def scene_of(url):
    async with websockets.connect(url.replace("http://", "ws://").rstrip("/") + "/ws", max_size=None) as page:
        await page.send('{"type":"hello"}')
        while True:
            message = await asyncio.wait_for(page.recv(), 30)
            if isinstance(message, str) and json.loads(message).get("type") == "scene":
                scene = json.loads(message)
                if scene["bodies"]:
                    return scene


def check_meshes(scene, what):
    """Each mesh's triangles index its vertices; each mesh shape names a mesh and has its bounding box
    as its size; returns the mesh shapes by model."""
    meshes = scene.get("meshes")
    if not meshes:
        problems.append(f"{what}: the scene message lists no meshes")
        return {}
    for k, m in enumerate(meshes):
        n = len(m["vertices"]) // 3
        if len(m["vertices"]) % 3 or len(m["triangles"]) % 3 or not m["triangles"]:
            problems.append(f"{what}: mesh {k} has {len(m['vertices'])} coordinates, {len(m['triangles'])} indices")
        if any(i < 0 or i >= n for i in m["triangles"]):
            problems.append(f"{what}: mesh {k} has a triangle index outside its {n} vertices")
    used = {}
    for model, shapes in [*enumerate(scene["models"]), ("world", scene["world"])]:
        for s in shapes:
            if s["kind"] != "mesh":
                continue
            used.setdefault(model, []).append(s["mesh"])
            v = meshes[s["mesh"]]["vertices"]
            size = [max(v[a::3]) - min(v[a::3]) for a in range(3)]
            if any(abs(a - b) > 1e-5 for a, b in zip(size, s["size"])):
                problems.append(f"{what}: a shape of model {model} has size {s['size']}, its mesh spans {size}")
    if sorted({k for ks in used.values() for k in ks}) != list(range(len(meshes))):
        problems.append(f"{what}: meshes sent that no shape draws, or shapes naming no mesh: {used}")
    return used


def stopped(run):
    status, err = run.stop()
    if status not in (0, 130):  # (130: stopped by Ctrl-C, as a person stops it)
        problems.append(f"ssx exited with {status}:\n{err}")


# the Crazyflie: four propellers, two meshes between them
run = ViewedRun(ssx, str(examples / "scenes" / "crazyflie_sdf.xml"), str(work / "cf"), "--duration", "60")
try:
    scene = asyncio.run(scene_of(run.url))
finally:
    stopped(run)
names = [b["name"] for b in scene["bodies"]]
by_name = {b["name"]: b["model"] for b in scene["bodies"]}
used = check_meshes(scene, "crazyflie")
props = [used.get(by_name.get(f"cf/crazyflie/m{i}_prop"), []) for i in range(1, 5)]
print(f"crazyflie: bodies {names}, {len(scene['meshes'])} meshes, propellers drawn by {props}")
if any(len(p) != 1 for p in props) or len({p[0] for p in props if p}) != 2:
    problems.append(f"the four propellers are not drawn by two meshes, each sent once: {props} (bodies {names})")

# the iiwa: sent, then drawn by a page
run = ViewedRun(ssx, str(examples / "scenes" / "iiwa_arm.xml"), str(work / "iiwa"), "--duration", "120")
page = None
try:
    scene = asyncio.run(scene_of(run.url))
    used = check_meshes(scene, "iiwa")
    triangles = [len(m["triangles"]) // 3 for m in scene["meshes"]]
    print(f"iiwa: {len(scene['bodies'])} bodies, meshes of {triangles} triangles, "
          f"scene message {len(json.dumps(scene)) // 1024} KiB")
    if len(triangles) != 8:
        problems.append(f"the iiwa's eight link meshes are {len(triangles)}")
    # its base, bolted to the world, is drawn with the world; its seven moving links with their bodies
    if len(used.get("world", [])) != 1 or len(scene["bodies"]) != 7:
        problems.append(f"the iiwa's base is not drawn with the world, or its links are not 7 bodies: {used}")
    page = headless_chromium(f"{work}/profile", 900, 700)
    page.get(run.url)
    wait_until(page, "return window.ssxViewer.state.bodies ? window.ssxViewer.state.bodies.length : 0",
               lambda v: v > 0, problems)
    wait_until(page, "return document.getElementById('robots').textContent", lambda v: v == "1", problems)  # one arm
    drawn = wait_until(page, "return window.ssxViewer.meshes.map((g) => g.attributes.position.count)",
                       lambda v: len(v) == len(triangles), problems)
    if drawn != [3 * t for t in triangles]:
        problems.append(f"the page's mesh geometries have {drawn} corners, not three per triangle of {triangles}")
    # the arm is drawn where its links are: a link's projected origin is not the background's colour
    wait_until(page, "return document.getElementById('time').textContent",
               lambda v: v not in ("-", "") and float(v) > 0.5, problems)
    result = page.execute_script("""
        const v = window.ssxViewer, n = v.state.bodies.length;
        v.draw();
        const background = v.pixel(5, innerHeight - 5), out = [];
        for (let i = 0; i < n; ++i) {
          const at = v.project(i);
          if (!at) continue;
          const c = v.pixel(at[0], at[1]);
          out.push(Math.abs(c[0] - background[0]) + Math.abs(c[1] - background[1]) + Math.abs(c[2] - background[2]));
        }
        return out;""")
    print(f"links' colour against the background's at their projected origins: {result}")
    if sum(1 for d in result if d > 30) < 0.7 * len(scene["bodies"]):
        problems.append(f"the arm's links are not drawn where they are: colour differences {result}")
    if screenshot:
        page.save_screenshot(screenshot)
finally:
    if page is not None:
        page.quit()
    stopped(run)

for p in problems:
    print("FAILED:", p)
sys.exit(1 if problems else 0)
