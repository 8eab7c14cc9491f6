#!/usr/bin/python3
"""The STM32F405 image's figures (docs/firmware.md, "Figures"), measured from a build tree:

  * flash and RAM of the board images at 2 and 4 axes (arm-none-eabi-size);
  * executed instructions of one device tick in the tick interrupt (run_tick: the device's
    tick, the enable and pen pins, the step pulse train, the trace record), per tick over a
    whole job streamed by the real host to the qemu image and a jog held and resumed by
    `ctl` (the hold plans a controlled stop in the tick: the worst tick), at 1, 2 and 4 axes
    (qemu's netduinoplus2 with the TCG plugin sim/cortex_m/plugin/insn_count.c), and the tick
    rate that leaves half of a 168 MHz Cortex-M4 free at one instruction per cycle, for the
    worst tick and for the 99.9th percentile;
  * the main stack's high-water mark (the stack is painted at reset; the image reports the
    highest word no longer painted);
  * Modbus RTU line use at 1 kHz: bytes and transactions per second of motion counted by the
    host's link, turned into wire time at 115200 and 1,000,000 baud (8E1: 11 bits a byte, and
    t3.5 of silence before each request and each answer), computed, not measured on the pty.

  figures.py BUILD_DIR [--assert BUDGETS]

BUILD_DIR is a tree configured with PATHSTREAM_CORTEX_M=ON (the default preset's). --assert
takes NAME=LIMIT pairs separated by commas and exits 1 when a figure is over its limit:
  tick_max_1, tick_max_2, tick_max_4   most instructions of one tick at 1, 2, 4 axes
  stack_2, stack_4                     stack high-water bytes at 2 and 4 axes
  flash_4, ram_4                       bytes of the 4-axis board image
"""
import json
import math
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

if len(sys.argv) < 2:
    sys.exit(__doc__)
build = os.path.abspath(sys.argv[1])
budgets = {}
if len(sys.argv) >= 4 and sys.argv[2] == "--assert":
    for item in sys.argv[3].split(","):
        name, _, value = item.partition("=")
        budgets[name.strip()] = float(value)

images = os.path.join(build, "firmware", "stm32f405")
plugin = os.path.join(build, "sim", "cortex_m", "libpathstream_insn_count.so")
pathstream = os.path.join(build, "host", "pathstream")
source = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
machine_2 = os.path.join(source, "examples", "machines", "pen_plotter.json")
for need in (images, plugin, pathstream):
    if not os.path.exists(need):
        sys.exit(f"figures.py: {need} not found: build {build} with PATHSTREAM_CORTEX_M=ON first")
tools = {t: "arm-none-eabi-" + t for t in ("size", "nm", "objdump")}
qemu = "qemu-system-arm"


def image(name):
    return os.path.join(images, name + ".elf")


def sizes(elf):
    out = subprocess.run([tools["size"], "-A", elf], capture_output=True, text=True, check=True).stdout
    sections = {m.group(1): int(m.group(2)) for m in re.finditer(r"^(\.\w+)\s+(\d+)", out, re.M)}
    text, data, bss = sections.get(".text", 0), sections.get(".data", 0), sections.get(".bss", 0)
    return text + data, data + bss


def tick_interval(elf):
    """run_tick's entry and the instruction tim5_irq returns to after calling it."""
    nm = subprocess.run([tools["nm"], elf], capture_output=True, text=True, check=True).stdout
    entry = next(int(m.group(1), 16) for m in re.finditer(r"^([0-9a-f]+) t (\S*run_tick\S*)$", nm, re.M))
    dis = subprocess.run([tools["objdump"], "-d", "--disassemble=tim5_irq", elf],
                         capture_output=True, text=True, check=True).stdout
    lines = dis.splitlines()
    for i, line in enumerate(lines):
        if re.search(r"\bbl\s+%x\b" % entry, line):
            after = re.match(r"\s*([0-9a-f]+):", lines[i + 1])
            return entry, int(after.group(1), 16)
    sys.exit(f"figures.py: no call of run_tick in tim5_irq of {elf}")


def drawing(axes):
    """A closed B-spline with `axes` coordinates per point: a rose in x and y, slower waves in
    z and a, a single wave for one axis; about four seconds at the profiles below."""
    points = []
    for k in range(48):
        t = 2 * math.pi * k / 48
        p = [100 + 60 * math.cos(3 * t) * math.cos(t), 100 + 60 * math.cos(3 * t) * math.sin(t),
             50 + 20 * math.sin(2 * t), 50 + 20 * math.cos(t)]
        points.append([round(c, 3) for c in (p[:axes] if axes > 1 else [100 + 80 * math.sin(t)])])
    return {"basis": "bspline", "subpaths": [{"points": points, "closed": True}]}


def profile(axes):
    with open(machine_2) as f:
        m = json.load(f)
    names = ["x", "y", "z", "a"]
    m["axes"] = [dict(m["axes"][0], name=names[a]) for a in range(axes)]
    return m


def measure(axes, work):
    """Streams a job to the qemu image of `axes` axes with the plugin counting run_tick."""
    name = {1: "pathstream-stm32f405-qemu-1axis", 2: "pathstream-stm32f405-qemu",
            4: "pathstream-stm32f405-qemu-4axes"}[axes]
    elf = image(name)
    entry, back = tick_interval(elf)
    d = os.path.join(work, f"axes{axes}")
    os.makedirs(d)
    machine, path = os.path.join(d, "machine.json"), os.path.join(d, "drawing.json")
    with open(machine, "w") as f:
        json.dump(profile(axes), f)
    job = drawing(axes)
    with open(path, "w") as f:
        json.dump(job, f)
    report, trace = os.path.join(d, "insn.txt"), os.path.join(d, "trace.txt")
    log = open(os.path.join(d, "qemu.log"), "w+")
    vm = subprocess.Popen([qemu, "-M", "netduinoplus2", "-display", "none", "-monitor", "none",
                           "-kernel", elf, "-serial", "pty", "-serial", "file:" + trace,
                           "-plugin", f"{plugin},interval={entry:#x}:{back:#x},out={report}"],
                          stdout=log, stderr=subprocess.STDOUT)
    try:
        pty = None
        for _ in range(200):
            log.seek(0)
            m = re.search(r"redirected to (/dev/pts/\d+)", log.read())
            if m:
                pty = m.group(1)
                break
            time.sleep(0.05)
        if pty is None:
            raise RuntimeError(f"qemu did not start: {open(log.name).read()}")
        held = os.open(pty, os.O_RDWR | os.O_NOCTTY)  # see tests/firmware/qemu_stream_test.sh
        time.sleep(1.2)
        target = f"modbus-rtu://{pty}?baud=115200"
        start = job["subpaths"][0]["points"][0]
        for a, value in enumerate(start):
            subprocess.run([pathstream, "ctl", "-m", machine, target, "position", profile(axes)["axes"][a]["name"],
                            str(value)], check=True, capture_output=True, timeout=60)
        done = subprocess.run([pathstream, "stream", path, "-m", machine, "-t", target, "--plan-first",
                               "--no-journal"], capture_output=True, text=True, timeout=300)
        if done.returncode != 0 or "finished" not in done.stdout:
            raise RuntimeError(f"stream at {axes} axes: {done.stdout}{done.stderr}")
        # The device's own worst tick: a hold plans a controlled stop, a resume the way back.
        # A jog held and resumed by ctl puts one of each in every run (on a serial line the
        # host's stream cannot share the line with ctl).
        first = profile(axes)["axes"][0]["name"]
        for command in (["jog", first, "-20", "--feed", "40", "--wait", "0"], ["hold"], ["resume"]):
            subprocess.run([pathstream, "ctl", "-m", machine, target] + command, check=True,
                           capture_output=True, timeout=60)
            time.sleep(0.2)
        for _ in range(100):
            state = subprocess.run([pathstream, "ctl", target, "status", "--json"], capture_output=True,
                                   text=True, timeout=60).stdout
            if json.loads(state)["state"] == "idle":
                break
            time.sleep(0.1)
        time.sleep(0.3)  # the trace's last notes
        os.close(held)
    finally:
        vm.send_signal(signal.SIGTERM)
        vm.wait(timeout=30)
    out = done.stdout
    link = re.search(r"link\s+(\d+) transactions, (\d+) retries.*?(\d+) bytes sent, (\d+) received", out)
    motion = float(re.search(r"executed\s+\d+ ticks \(([\d.]+) s of motion\)", out).group(1))
    underruns = int(re.search(r"device\s+(\d+) underruns", out).group(1))
    with open(report) as f:
        row = next(line.split() for line in f if line.startswith("insn_count interval"))
    calls, low, median, p99, p999, high, total = (int(v) for v in row[4:11])
    stack = max((int(m.group(1)) for m in re.finditer(r"^# stack_used (\d+) of", open(trace).read(), re.M)),
                default=0)
    return {"axes": axes, "calls": calls, "min": low, "median": median, "p99": p99, "p999": p999,
            "max": high, "mean": total / calls, "stack": stack, "motion_s": motion,
            "transactions": int(link.group(1)), "retries": int(link.group(2)),
            "sent": int(link.group(3)), "received": int(link.group(4)), "underruns": underruns}


with tempfile.TemporaryDirectory(prefix="pathstream-figures-") as work:
    results = [measure(axes, work) for axes in (1, 2, 4)]

print("Image sizes (board images, arm-none-eabi-g++ -O2, 168 MHz profile; the stack, 8 KiB, comes on top of RAM)")
print(f"{'image':34} {'flash':>9} {'RAM':>9}")
figures = {}
for name, axes in (("pathstream-stm32f405", 2), ("pathstream-stm32f405-4axes", 4)):
    flash, ram = sizes(image(name))
    figures[f"flash_{axes}"], figures[f"ram_{axes}"] = flash, ram
    print(f"{name + '.elf':34} {flash:>9,} {ram:>9,}")
print()
print("One device tick in the tick interrupt (run_tick), executed instructions per tick: a whole job and a held jog")
print(f"{'axes':>4} {'ticks':>7} {'min':>6} {'median':>7} {'p99':>6} {'p99.9':>6} {'max':>7} {'mean':>7}"
      f" {'tick rate, 50 % of 168 MHz free: at p99.9':>42} {'at max':>10} {'stack used':>11}")
for r in results:
    figures[f"tick_max_{r['axes']}"] = r["max"]
    figures[f"stack_{r['axes']}"] = r["stack"]
    print(f"{r['axes']:>4} {r['calls']:>7,} {r['min']:>6,} {r['median']:>7,} {r['p99']:>6,} {r['p999']:>6,}"
          f" {r['max']:>7,} {r['mean']:>7.1f} {0.5 * 168e3 / r['p999']:>38,.1f} kHz"
          f" {0.5 * 168e3 / r['max']:>6,.1f} kHz {r['stack']:>6,} B")
print()
print("Modbus RTU line use at a 1 kHz tick, per second of motion (8E1: 11 bits a byte; t3.5 before each frame)")
print(f"{'axes':>4} {'transactions':>12} {'bytes out':>10} {'bytes in':>9} {'115200 baud':>12} {'1000000 baud':>13}")
for r in results:
    per_s = 1.0 / r["motion_s"]
    tx, sent, received = r["transactions"] * per_s, r["sent"] * per_s, r["received"] * per_s
    use = []
    for baud in (115200, 1000000):
        t35 = 1750e-6 if baud > 19200 else 38.5 / baud
        wire = (sent + received) * 11 / baud + 2 * tx * t35
        use.append(f"{100 * wire:.1f} %")
    print(f"{r['axes']:>4} {tx:>12.1f} {sent:>10,.0f} {received:>9,.0f} {use[0]:>12} {use[1]:>13}")
retries = sum(r["retries"] for r in results)
underruns = sum(r["underruns"] for r in results)
print(f"\n(link retries in the three jobs: {retries}; device underruns: {underruns})")

failed = [f"{k} = {figures[k]:,.0f} over {v:,.0f}" for k, v in budgets.items() if figures.get(k, 0) > v]
unknown = [k for k in budgets if k not in figures]
if unknown:
    sys.exit(f"figures.py: unknown budget {', '.join(unknown)}")
if failed:
    print("FAIL " + "; ".join(failed))
    sys.exit(1)
if budgets:
    print("figures within their budgets: " + ", ".join(f"{k} <= {v:,.0f}" for k, v in budgets.items()))
