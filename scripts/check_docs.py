#!/usr/bin/env python3
"""Every code block in README.md and docs/*.md is tested, or says why it is not.

    check_docs.py SOURCE_DIR BUILD_DIR [WORK_DIR]

Each fenced block is preceded by a marker line `<!-- doc-test: KIND -->`:

  run            sh: each command runs (bash -e); python: the block runs; cpp: compiled against the
                 build and run. All in WORK_DIR, where build/, examples/, tests/ and docs/ are links to the
                 tree, so outputs land there and never in the repository.
  run, prints: RE  as run, and what it prints matches the regular expression RE (a figure the text
                 beside the block quotes)
  output         the block is `$ COMMAND` and then exactly what the command prints (stdout and
                 stderr), run as for `run`
  validate       an XML scene: `ssx validate` accepts it
  validate-sweep a sweep file, kept beside examples/sweeps: `ssx sweep --check` accepts it
  fragment       XML that is part of a file (an element of a scene, an artifact's sensor): it parses
  compile        cpp: compiled (not linked) against the build: a plugin or part of a program
  same as PATH   the block is the file PATH of the repository, to the byte
  not run: WHY   not run, for the reason given

Every relative link ([text](path) or ![alt](path)) must name a file of the repository.

A block without a marker, a marker without a block, an unknown kind or a failing block is an error
`file:line: error: ...`; the exit status is 1 when there was any.
"""
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import xml.dom.minidom

MARKER = re.compile(r"^<!-- doc-test: (.*?) -->$")


def blocks(path):
    """(line of the fence, language, text, marker or None, line of the marker)"""
    lines = path.read_text().split("\n")
    out, i = [], 0
    while i < len(lines):
        if lines[i].startswith("```"):
            lang = lines[i][3:].strip()
            start = i
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            text = "\n".join(lines[start + 1:j]) + "\n"
            k = start - 1
            while k >= 0 and not lines[k].strip():
                k -= 1
            m = MARKER.match(lines[k].strip()) if k >= 0 else None
            out.append((start + 1, lang, text, m.group(1) if m else None, k + 1))
            i = j + 1
        else:
            i += 1
    return out


class Checker:
    def __init__(self, source, build, work):
        self.source, self.build, self.work = source, build, work
        self.errors = 0
        for name, target in (("build", build), ("examples", source / "examples"), ("tests", source / "tests"),
                             ("docs", source / "docs")):
            link = work / name
            if not link.exists():
                link.symlink_to(target)
        self.env = dict(os.environ)
        self.env["PYTHONPATH"] = str(build / "python")
        self.env.pop("SSX_PLUGIN_PATH", None)

    def error(self, where, message):
        print(f"{where}: error: {message}")
        self.errors += 1

    def run(self, command, where, **kw):
        r = subprocess.run(command, cwd=self.work, env=self.env, capture_output=True, text=True, timeout=600, **kw)
        if r.returncode != 0:
            self.error(where, f"exit status {r.returncode}\n{r.stdout}{r.stderr}")
        return r

    def cpp(self, text, where, link):
        src = self.work / "doc_block.cpp"
        src.write_text(text)
        # (and the robots' parts, as installed: <ssx/quadrotor/...>, <ssx/diff_drive/...>)
        includes = ["-I", str(self.source / "libssx/include"), "-I", str(self.build / "libssx/include"),
                    "-I", str(self.build / "plugins/quadrotor/include"), "-I", str(self.build / "plugins/diff_drive/include"),
                    "-isystem", "/usr/include/eigen3"]
        if not link:
            self.run(["c++", "-std=c++20", "-fsyntax-only", *includes, str(src)], where)
            return
        exe = self.work / "doc_block"
        built = self.run(["c++", "-std=c++20", "-O1", *includes, str(src), "-o", str(exe), "-L", str(self.build / "lib"),
                          "-lssx", f"-Wl,-rpath,{self.build / 'lib'}"], where)
        if built.returncode == 0:
            self.run([str(exe)], where)

    def links(self, doc):
        rel = doc.relative_to(self.source)
        for number, line in enumerate(doc.read_text().split("\n"), 1):
            for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", line):
                if re.match(r"^[a-z]+:", target):
                    continue  # a URL
                if not (doc.parent / target).exists():
                    self.error(f"{rel}:{number}", f"a link to '{target}', which is not in the repository")

    def check(self, doc):
        self.links(doc)
        rel = doc.relative_to(self.source)
        for line, lang, text, marker, marker_line in blocks(doc):
            where = f"{rel}:{line}"
            if marker is None:
                self.error(where, "a code block without a <!-- doc-test: ... --> line before it (run, output, "
                                  "validate, validate-sweep, fragment, compile, same as PATH, or not run: WHY)")
                continue
            if marker == "run" or marker.startswith("run, prints: "):
                expected = marker[len("run, prints: "):] if marker != "run" else None
                r = None
                if lang == "sh":
                    r = self.run(["bash", "-e", "-c", text], where)
                elif lang == "python":
                    r = self.run(["/usr/bin/python3", "-c", text], where)
                elif lang == "cpp":
                    self.cpp(text, where, link=True)
                else:
                    self.error(where, f"'run' takes sh, python or cpp blocks, not '{lang}'")
                if expected is not None and (r is None or not re.search(expected, r.stdout)):
                    self.error(where, f"prints no match for '{expected}':\n{r.stdout if r else ''}")
            elif marker == "output":
                first, _, expected = text.partition("\n")
                if not first.startswith("$ "):
                    self.error(where, "an 'output' block starts with '$ COMMAND'")
                    continue
                r = subprocess.run(["bash", "-c", first[2:] + " 2>&1"], cwd=self.work, env=self.env,
                                   capture_output=True, text=True, timeout=600)
                if r.stdout != expected:
                    self.error(where, f"'{first[2:]}' prints something else now:\n{r.stdout}")
            elif marker == "validate":
                scene = self.work / "doc_scene.xml"
                scene.write_text(text)
                self.run([str(self.build / "bin/ssx"), "validate", str(scene)], where)
            elif marker == "validate-sweep":
                sweeps = self.work / "sweeps"
                sweeps.mkdir(exist_ok=True)
                if not (self.work / "scenes").exists():
                    (self.work / "scenes").symlink_to(self.source / "examples" / "scenes")
                (sweeps / "doc_sweep.xml").write_text(text)
                self.run([str(self.build / "bin/ssx"), "sweep", str(sweeps / "doc_sweep.xml"), "--check"], where)
            elif marker == "fragment":
                try:
                    xml.dom.minidom.parseString(f"<fragment>{text}</fragment>")
                except Exception as e:  # noqa: BLE001 (any parse error is the finding)
                    self.error(where, f"not well-formed XML: {e}")
            elif marker == "compile":
                self.cpp(text, where, link=False)
            elif marker.startswith("same as "):
                path = self.source / marker[len("same as "):]
                if not path.is_file() or path.read_text() != text:
                    self.error(where, f"the block is not {marker[len('same as '):]} as it is now")
            elif marker.startswith("not run: ") and len(marker) > len("not run: ") + 3:
                pass
            else:
                self.error(f"{rel}:{marker_line}", f"unknown doc-test marker '{marker}'")


def main():
    source, build = pathlib.Path(sys.argv[1]).resolve(), pathlib.Path(sys.argv[2]).resolve()
    work = pathlib.Path(sys.argv[3]) if len(sys.argv) > 3 else pathlib.Path(tempfile.mkdtemp(prefix="ssx_docs_"))
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    checker = Checker(source, build, work.resolve())
    docs = [source / "README.md", *sorted((source / "docs").glob("*.md"))]
    count = 0
    for doc in docs:
        count += len(blocks(doc))
        checker.check(doc)
    print(f"{count} code blocks in {len(docs)} documents, {checker.errors} error(s)")
    sys.exit(1 if checker.errors else 0)


if __name__ == "__main__":
    main()
