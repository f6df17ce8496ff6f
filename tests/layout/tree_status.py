#!/usr/bin/env python3
"""A whole ctest run leaves the source tree as it found it: no file written, changed or removed.

  tree_status.py ROOT before STATE   records `git status` (ignored files too) into STATE
  tree_status.py ROOT after STATE    compares with it; new or changed entries fail, named

Run by ctest as the setup and cleanup of a fixture that every test requires, so the comparison
is made once every test has finished. Entries already there before the run (a developer's own
edits) are not held against the tests. Outside a git checkout (a source archive) it says so and passes.
"""
import os
import pathlib
import subprocess
import sys


def status(root):
    run = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--ignored", "--untracked-files=all"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        return None
    return set(line for line in run.stdout.splitlines() if line)


def main():
    root, mode, state = pathlib.Path(sys.argv[1]), sys.argv[2], pathlib.Path(sys.argv[3])
    now = status(root)
    if now is None:
        print(f"{root}: not a git checkout; nothing to compare")
        return 0
    # the build tree may be inside the source tree (ignored): what is written there is its own
    # (paths compared as written, not resolved: a link the tests made in the build tree, to the
    # source's docs say, is the build tree's entry, wherever it points)
    build = pathlib.Path(os.path.abspath(sys.argv[4])) if len(sys.argv) > 4 else None
    def inside_build(entry):
        if build is None:
            return False
        path = pathlib.Path(os.path.abspath(root / entry[3:].strip('"')))
        return path == build or build in path.parents or path in build.parents
    now = {e for e in now if not inside_build(e)}
    if mode == "before":
        state.parent.mkdir(parents=True, exist_ok=True)
        state.write_text("\n".join(sorted(now)) + "\n")
        print(f"{len(now)} entries in git status before the tests")
        return 0
    if not state.exists():
        print(f"error: {state} was not recorded (the fixture's setup did not run)")
        return 1
    before = set(line for line in state.read_text().splitlines() if line)
    new = sorted(now - before)
    if new:
        print("error: the tests left the source tree changed (each test writes only in its own temporary directory):")
        for entry in new:
            print("  " + entry)
        return 1
    print(f"the source tree is as it was ({len(now)} entries in git status, none new)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
