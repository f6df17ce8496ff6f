#!/usr/bin/env python3
"""ctest (plugins/ros2/ssx_msgs): the ROS 2 package a ROS user builds to read ssx's own messages says
field for field what ssx puts on DDS (plugins/ros2/idl/ros2_messages.idl, module ssx_msgs): the same
messages, fields in the same order, of the same types; and it lists every message in its CMakeLists.

    ssx_msgs_test.py SOURCE_DIR
"""
import os
import re
import sys

IDL_TYPES = {"double": "float64", "float": "float32", "string": "string", "octet": "uint8", "boolean": "bool",
             "int32": "int32", "uint32": "uint32", "std_msgs::msg::dds_::Header_": "std_msgs/Header"}


def idl_type(t):
    seq = re.fullmatch(r"sequence<(.+)>", t)
    if seq:
        return idl_type(seq.group(1)) + "[]"
    return IDL_TYPES.get(t, t[:-1] if t.endswith("_") else t)


def idl_structs(path):
    text = open(path).read()
    module = re.search(r"module ssx_msgs \{ module msg \{ module dds_ \{(.*?)\}; \}; \};", text, re.S).group(1)
    structs = {}
    for name, body in re.findall(r"@final struct (\w+)_ \{(.*?)\};", module, re.S):
        fields = [f.strip() for f in body.split(";") if f.strip()]
        structs[name] = [(idl_type(f.rsplit(None, 1)[0]), f.rsplit(None, 1)[1]) for f in fields]
    return structs


def msg_fields(path):
    fields = []
    for line in open(path):
        line = line.split("#", 1)[0].strip()
        if line:
            t, n = line.split()[:2]
            fields.append((t, n))
    return fields


def main():
    src = sys.argv[1]
    idl = idl_structs(os.path.join(src, "plugins/ros2/idl/ros2_messages.idl"))
    pkg = os.path.join(src, "plugins/ros2/ssx_msgs")
    msgs = {f[:-4]: msg_fields(os.path.join(pkg, "msg", f)) for f in os.listdir(os.path.join(pkg, "msg"))}
    cmake = open(os.path.join(pkg, "CMakeLists.txt")).read()
    failures = 0
    if sorted(idl) != sorted(msgs):
        print(f"FAILED: messages in the IDL {sorted(idl)}, in the package {sorted(msgs)}")
        failures += 1
    for name in sorted(set(idl) & set(msgs)):
        ok = idl[name] == msgs[name]
        print(f"{'ok' if ok else 'FAILED'}: {name}: {msgs[name]}" + ("" if ok else f" against the IDL's {idl[name]}"))
        failures += not ok
        if f'"msg/{name}.msg"' not in cmake:
            print(f"FAILED: {name}.msg is not in the package's CMakeLists.txt")
            failures += 1
    print(f"{len(msgs)} messages, {failures} problem(s)")
    return 1 if failures or not msgs else 0


if __name__ == "__main__":
    sys.exit(main())
