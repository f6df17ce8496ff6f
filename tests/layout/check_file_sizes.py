#!/usr/bin/env python3
"""No source file in libssx/, plugins/, cli/ or python/ is over 600 lines (a file that grows past
it holds more than one concept: split it). Prints each one over and exits 1 when there is any."""
import pathlib
import sys

LIMIT = 600
root = pathlib.Path(sys.argv[1])
over = []
for top in ("libssx", "plugins", "cli", "python"):
    for source in sorted((root / top).rglob("*")):
        if source.suffix not in (".cpp", ".hpp", ".h", ".py") or not source.is_file():
            continue
        lines = source.read_text(errors="replace").count("\n")
        if lines > LIMIT:
            over.append(f"error: {source.relative_to(root)}: {lines} lines (at most {LIMIT})")
print("\n".join(over + [f"{len(over)} source files over {LIMIT} lines"]))
sys.exit(1 if over else 0)
