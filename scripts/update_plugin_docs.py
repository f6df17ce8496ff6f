#!/usr/bin/env python3
"""Rewrites the parameter tables of the built-in plugins in docs/scene-format.md from their
declarations (`ssx plugins --params NAME`). The test `the built-in plugin tables in the docs are
their declarations` fails when the two differ.

    scripts/update_plugin_docs.py [path/to/ssx]   (default: build/bin/ssx)
"""
import pathlib
import re
import subprocess
import sys

root = pathlib.Path(__file__).resolve().parent.parent
ssx = sys.argv[1] if len(sys.argv) > 1 else str(root / "build" / "bin" / "ssx")
doc = root / "docs" / "scene-format.md"
text = doc.read_text()


def table(match):
    name = match.group(1)
    out = subprocess.run([ssx, "plugins", "--params", name], capture_output=True, text=True)
    if out.returncode != 0:
        print(f"{name}: not built here, table left as it is", file=sys.stderr)
        return match.group(0)
    body = out.stdout.split("\n\n", 1)[1]
    return f"<!-- parameters:{name} -->\n{body}<!-- end parameters:{name} -->"


text = re.sub(r"<!-- parameters:(\w+) -->\n.*?<!-- end parameters:\1 -->", table, text, flags=re.S)
doc.write_text(text)
