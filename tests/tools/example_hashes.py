#!/usr/bin/env python3
"""The state hash of every example scene after its first 300 steps, against the hashes kept in
tests/data/example_state_hashes.txt: a change that should not change behaviour (moving files,
restructuring, a faster path) must leave every one bit for bit as it was.

  example_hashes.py ROOT WORKDIR           compare (exit 1, naming the scenes that differ)
  example_hashes.py ROOT WORKDIR --update  write the file anew (after a change meant to alter behaviour)

Each scene runs on 2 threads in WORKDIR (what its loggers write stays there), its outputs and
pictures left to the scene; scenes that need a plugin this build lacks (ROS) are skipped, said.
"""
import os
import pathlib
import sys

import ssx

STEPS = 300


def scenes(root):
    for folder in ("examples/scenes", "examples/ground"):
        yield from sorted((root / folder).glob("*.xml"))


def main():
    root, work = pathlib.Path(sys.argv[1]).resolve(), pathlib.Path(sys.argv[2]).resolve()
    update = "--update" in sys.argv[3:]
    kept = root / "tests" / "data" / "example_state_hashes.txt"
    work.mkdir(parents=True, exist_ok=True)
    os.chdir(work)
    now = {}
    for scene in scenes(root):
        name = str(scene.relative_to(root))
        try:
            env = ssx.load_scene(str(scene), threads=2)
        except Exception as e:  # noqa: BLE001 - said, and the comparison fails on it below
            print(f"{name}: does not load: {e}")
            continue
        env.step(STEPS)
        now[name] = f"{env.state_hash():016x}"
        env.close() if hasattr(env, "close") else None
    if update:
        kept.write_text("".join(f"{k} {v}\n" for k, v in sorted(now.items())))
        print(f"{kept}: {len(now)} hashes written")
        return 0
    expected = dict(line.split() for line in kept.read_text().splitlines() if line.strip())
    bad = 0
    for name, value in sorted(expected.items()):
        got = now.get(name)
        if got != value:
            print(f"error: {name}: state hash after {STEPS} steps is {got}, was {value}")
            bad += 1
    for name in sorted(set(now) - set(expected)):
        print(f"error: {name}: no hash kept (run with --update and commit the file)")
        bad += 1
    print(f"{len(expected)} example scenes, {bad} differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
