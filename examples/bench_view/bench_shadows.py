#!/usr/bin/env python3
"""What the page's shadows cost: a recording played by `ssx replay RECORDING --view` in headless
Chromium (software WebGL), the page's frame rate read each second for 6 s after 4 s, with
?shadows=0 and ?shadows=1 in turns, ROUNDS times. Needs Debian's chromium, chromium-driver and
python3-selenium. Prints per page `shadows=0|1 fps=[...]`.

    bench_shadows.py SSX RECORDING [--rounds R]

docs/viewer.md's figures: a recording of 200 robots over 60 s (`ssx run` of
tests/unit/plugins/viewer/viewer_replay_test.py's scene with --duration 60 --record)."""
import argparse
import pathlib
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "tests" / "unit" / "plugins" / "viewer"))
from viewer_util import ViewedRun, headless_chromium  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("ssx")
parser.add_argument("recording")
parser.add_argument("--rounds", type=int, default=2)
args = parser.parse_args()
page = headless_chromium(pathlib.Path("/tmp") / "ssx_bench_shadows_profile")
run = ViewedRun(args.ssx, None, None, replay=args.recording)
try:
    for _ in range(args.rounds):
        for shadows in (0, 1):
            page.get(f"{run.url}?shadows={shadows}")
            time.sleep(4)
            fps = []
            for _ in range(6):
                time.sleep(1.0)
                fps.append(int(page.execute_script("return document.getElementById('fps').textContent") or 0))
            print(f"shadows={shadows} fps={fps} (the page says shadows "
                  f"{page.execute_script('return window.ssxViewer.state.shadows')})")
finally:
    page.quit()
    run.stop()
