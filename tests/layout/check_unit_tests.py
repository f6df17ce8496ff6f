#!/usr/bin/env python3
"""Every unit of libssx/src and plugins/ has a test file of its name under tests/unit/:
libssx/src/X.cpp -> tests/unit/X_test.cpp, plugins/P/X.cpp -> tests/unit/plugins/P/X_test.cpp, a
plugin made of one file (plugins/P/P.cpp) -> tests/unit/plugins/P_test.cpp. A unit that can only be
tested with processes around it (the ROS 1 bridge needs a master and a peer, the viewer a browser)
has a script of its name instead, X_test.sh or X_test.py, which ctest runs. Prints what is missing and exits 1 when anything is;
also that every test file is built or run, and that no test case's name holds a ';' (ctest reads
the list catch_discover_tests writes as a CMake list, so such a name becomes two tests that both fail)."""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
missing = []
units = 0
for source in sorted((root / "libssx" / "src").rglob("*.cpp")):
    units += 1
    relative = source.relative_to(root / "libssx" / "src")
    test = root / "tests" / "unit" / relative.parent / (source.stem + "_test.cpp")
    if not any(t.is_file() for t in (test, test.with_suffix(".sh"), test.with_suffix(".py"))):
        missing.append(f"{source.relative_to(root)}: no {test.relative_to(root)}")
for source in sorted((root / "plugins").rglob("*.cpp")):
    units += 1
    relative = source.relative_to(root)
    plugin = relative.parts[1]
    candidates = [root / "tests" / "unit" / relative.parent / (source.stem + "_test.cpp")]
    if source.stem == plugin:
        candidates.append(root / "tests" / "unit" / "plugins" / (plugin + "_test.cpp"))
    if not any(c.is_file() or c.with_suffix(".sh").is_file() or c.with_suffix(".py").is_file() for c in candidates):
        missing.append(f"{relative}: no {candidates[-1].relative_to(root)}")

# and every test file is compiled into the test binary, or run by ctest
listed = (root / "tests" / "CMakeLists.txt").read_text()
for test in sorted([*(root / "tests" / "unit").rglob("*_test.cpp"), *(root / "tests" / "unit").rglob("*_test.sh"),
                    *(root / "tests" / "unit").rglob("*_test.py")]):
    if str(test.relative_to(root / "tests")) not in listed:
        missing.append(f"{test.relative_to(root)}: not in tests/CMakeLists.txt")

# a Catch test case's name, as the first string literal of TEST_CASE( or SCENARIO(
name = re.compile(r'\b(?:TEST_CASE|SCENARIO|TEMPLATE_TEST_CASE)\s*\(\s*"((?:[^"\\]|\\.)*)"')
for test in sorted((root / "tests").rglob("*.cpp")):
    text = test.read_text(errors="replace")
    for m in name.finditer(text):
        if ";" in m.group(1):
            line = text.count("\n", 0, m.start()) + 1
            missing.append(f"{test.relative_to(root)}:{line}: test case name holds ';' (ctest splits it in two): "
                           f"use a comma")

for m in missing:
    print(f"error: {m}")
print(f"{units} units, {len(missing)} problems")
sys.exit(1 if missing else 0)
