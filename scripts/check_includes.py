#!/usr/bin/python3
"""Which folder includes which: every `#include "pathstream/..."` in production code, as an
arrow between layers: core (firmware_core), hal, firmware (the microcontroller images, on core
and hal alone), machine (what host and device share), host
(the libraries under host/src but its CLI and web server), linux_device (the device runtime),
sim (what stands in for hardware), app (host/src/cli, host/src/serve, host/src/main.cpp and
device_cli: the executables). ALLOWED says which arrows
may exist: down only, and host and the device runtime never into each other. Arrows that break
it today are listed in scripts/include_arrows_known.txt with their counts, to be removed as the
layers are separated: a new one, or a known one that grows, fails.

  check_includes.py SOURCE_DIR          exit 1 on an upward arrow not known, or one that grew
  check_includes.py SOURCE_DIR --table  prints every arrow with its count
"""
import collections
import os
import re
import sys

RANK = {"core": 0, "hal": 1, "firmware": 2, "machine": 3, "host": 4, "linux_device": 5, "sim": 6,
        "app": 7}
ALLOWED = {
    "core": set(),
    "hal": {"core"},
    "firmware": {"core", "hal"},
    "machine": {"core", "hal"},
    "host": {"core", "hal", "machine"},
    "linux_device": {"core", "hal", "machine"},
    "sim": {"core", "hal", "machine", "linux_device"},
    "app": {"core", "hal", "machine", "host", "linux_device", "sim"},
}
source = sys.argv[1]


def layer_of_file(path):
    rel = os.path.relpath(path, source)
    if rel.startswith("firmware_core/"):
        return "core"
    if rel.startswith("hal/"):
        return "hal"
    if rel.startswith("firmware/"):
        return "firmware"
    if rel.startswith("machine/"):
        return "machine"
    if rel.startswith(("host/src/cli/", "host/src/serve/", "device_cli/")) or rel == "host/src/main.cpp":
        return "app"
    if rel.startswith("host/"):
        return "host"
    if rel.startswith("linux_device/"):
        return "linux_device"
    if rel.startswith("sim/"):
        return "sim"
    return None


def layer_of_include(name):
    part = name.split("/")
    if len(part) == 2 or part[1] == "device":
        return "core"
    return {"hal": "hal", "machine": "machine", "host": "host", "linux_device": "linux_device", "sim": "sim"}.get(part[1])


arrows = collections.Counter()
for folder in ("firmware_core", "hal", "firmware", "machine", "host", "linux_device", "sim", "device_cli"):
    for root, dirs, files in os.walk(os.path.join(source, folder)):
        dirs[:] = [d for d in dirs if d not in ("node_modules", "build")]
        for f in files:
            if not f.endswith((".cpp", ".hpp", ".h", ".c")):
                continue
            path = os.path.join(root, f)
            frm = layer_of_file(path)
            with open(path, encoding="utf-8", errors="replace") as text:
                for m in re.finditer(r'^\s*#\s*include\s+"(pathstream/[^"]+)"', text.read(), re.M):
                    to = layer_of_include(m.group(1))
                    if frm and to and frm != to:
                        arrows[(frm, to)] += 1

if "--table" in sys.argv:
    for (frm, to), n in sorted(arrows.items(), key=lambda a: (RANK[a[0][0]], RANK[a[0][1]])):
        print(f"{frm} -> {to}: {n}{'' if to in ALLOWED[frm] else '  (not allowed)'}")
    sys.exit(0)

known = {}
with open(os.path.join(source, "scripts/include_arrows_known.txt")) as f:
    for line in f:
        line = line.split("#")[0].strip()
        if line:
            frm, _, to, n = line.replace(":", " ").split()
            known[(frm, to)] = int(n)
bad = 0
for (frm, to), n in sorted(arrows.items()):
    if to in ALLOWED[frm]:
        continue
    if n > known.get((frm, to), 0):
        print(f"include not allowed: {frm} -> {to}: {n} (known: {known.get((frm, to), 0)}); "
              f"run scripts/check_includes.py . --table")
        bad += 1
for (frm, to), n in sorted(known.items()):
    if arrows.get((frm, to), 0) < n:
        print(f"fewer includes not allowed {frm} -> {to}: {arrows.get((frm, to), 0)} (known {n}): "
              "lower the count in scripts/include_arrows_known.txt")
        bad += 1
print(f"include arrows: {sum(arrows.values())} includes across layers, {bad} problems")
sys.exit(1 if bad else 0)
