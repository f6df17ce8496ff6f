#!/usr/bin/env python3
"""libssx's folders depend downwards only (docs/architecture.md draws them): a file in one folder
includes the private headers of its own folder and of the folders below it, never of one above or
beside it. Prints each include that breaks the order, with its file and line, and exits 1 if any.
Also: every source is in a folder (none directly in libssx/src)."""
import pathlib
import re
import sys

# each folder and the folders it may include from (besides itself)
BELOW = {
    "base": set(),
    "plugin": {"base"},
    "robot": {"base"},
    "render": {"base"},
    "engines": {"base", "render"},
    "world": {"base", "plugin", "robot", "engines", "render"},
    "record": {"base"},
    "scene": {"base", "plugin", "robot", "engines", "render", "world", "record"},
    "learn": {"base", "plugin", "robot", "engines", "render", "world", "record", "scene"},
}

root = pathlib.Path(sys.argv[1])
src = root / "libssx" / "src"
include = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
problems = []
files = 0
for path in sorted(src.rglob("*")):
    if path.suffix not in (".cpp", ".hpp", ".h") or not path.is_file():
        continue
    files += 1
    relative = path.relative_to(src)
    if len(relative.parts) == 1:
        problems.append(f"libssx/src/{relative}: not in a folder (one of {', '.join(BELOW)})")
        continue
    folder = relative.parts[0]
    if folder not in BELOW:
        problems.append(f"libssx/src/{relative}: folder '{folder}' is not in the drawing (tests/layout/check_folders.py)")
        continue
    for number, line in enumerate(path.read_text().splitlines(), 1):
        m = include.match(line)
        if not m:
            continue
        target = m.group(1)
        first = target.split("/")[0]
        if "/" not in target:
            if not (path.parent / target).is_file():
                problems.append(f"libssx/src/{relative}:{number}: \"{target}\" names no folder")
            continue
        if first not in BELOW:
            continue  # not one of libssx's private folders
        # the builder makes the world from the model alone: of scene/, only scene.cpp (which
        # reads and builds) includes the XML reader
        if (folder == "scene" and target.startswith("scene/xml/") and relative.parts[1] != "xml"
                and relative.name != "scene.cpp"):
            problems.append(f"libssx/src/{relative}:{number}: error: includes the XML reader \"{target}\": "
                            f"the builder works from the scene model alone")
        if folder == "scene" and relative.parts[1] == "xml" and target.startswith("scene/builder"):
            problems.append(f"libssx/src/{relative}:{number}: error: the XML reader includes the builder \"{target}\"")
        if first != folder and first not in BELOW[folder]:
            problems.append(f"libssx/src/{relative}:{number}: error: {folder}/ includes \"{target}\" from {first}/, "
                            f"which is not below it")
for p in problems:
    print(p)
print(f"{files} files in {len(BELOW)} folders, {len(problems)} includes against the order")
sys.exit(1 if problems else 0)
