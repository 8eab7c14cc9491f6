#!/usr/bin/env python3
"""Time from launch to the first span on the wire, and peak RSS, of `pathstream stream` for
generated jobs of 10k, 100k and 1M points streamed to `pathstream device` (Modbus TCP, time
scale 1000), planned while streaming and with --plan-first (the whole plan first).

usage: scripts/stream_figures.py BUILD_DIR [POINTS ...]   (docs/cli.md, "Planning while streaming")

The job: a smooth random walk of POINTS points 0.25 mm apart (a CSV read as a B-spline), one
subpath. "first span" is the `t` of the stream's job_start event: written after the first
batch of spans was acknowledged, counted from the command's start. Peak RSS from
/usr/bin/time -v.
"""
import json
import math
import os
import random
import re
import subprocess
import sys
import tempfile
import time


def write_walk(path, points, seed=1):
    rng = random.Random(seed)
    x, y, heading = 200.0, 200.0, 0.0
    with open(path, "w") as f:
        f.write("x,y\n")
        for _ in range(points):
            f.write(f"{x:.4f},{y:.4f}\n")
            heading += rng.uniform(-0.05, 0.05)
            x += 0.25 * math.cos(heading)
            y += 0.25 * math.sin(heading)
            if not (20 < x < 380 and 20 < y < 380):
                heading += math.pi / 2  # turn away from the edge, smoothly over the next points
    return "200,200"


def start_device(binary, machine, position, work):
    log = open(os.path.join(work, "device.ndjson"), "w")
    device = subprocess.Popen([binary, "device", "-m", machine, "--no-gpio", "--tcp", "127.0.0.1:0",
                               "--position", position, "--time-scale", "1000", "--log-json"],
                              stdout=log, stderr=subprocess.DEVNULL)
    for _ in range(200):
        with open(log.name) as f:
            m = re.search(r'"url":"(modbus-tcp:[^"]*)"', f.read())
        if m:
            return device, m.group(1)
        time.sleep(0.05)
    device.kill()
    raise SystemExit("the device did not start")


def run(binary, machine, csv, position, work, plan_first):
    device, url = start_device(binary, machine, position, work)
    events = os.path.join(work, "events.ndjson")
    command = ["/usr/bin/time", "-v", binary, "stream", csv, "--csv-basis", "bspline", "--keep-order", "--lead-in",
               "-m", machine, "-t", url, "--events", events]
    if plan_first:
        command.append("--plan-first")
    t0 = time.monotonic()
    done = subprocess.run(command, cwd=work, capture_output=True, text=True)
    wall = time.monotonic() - t0
    device.terminate()
    device.wait()
    if done.returncode != 0:
        message = [line for line in done.stderr.splitlines() if line.startswith("pathstream:")]
        return {"error": f"exit {done.returncode} after {wall:.1f} s: {message[-1:]}"}
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr).group(1))
    first = None
    with open(events) as f:
        for line in f:
            e = json.loads(line)
            if e["event"] == "job_start":
                first = e["t"]
                break
    executed = re.search(r"executed\s+(\d+) ticks", done.stdout + done.stderr).group(1)
    return {"first_span_s": first, "peak_rss_mb": rss_kb / 1024, "wall_s": wall, "ticks": int(executed)}


def main():
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    build = sys.argv[1]
    counts = [int(n) for n in sys.argv[2:]] or [10000, 100000, 1000000]
    binary = os.path.join(build, "host", "pathstream")
    source = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    machine = os.path.join(source, "examples", "machines", "pen_plotter.json")
    print(f"{'points':>8} {'mode':<20} {'first span s':>12} {'peak RSS MB':>11} {'wall s':>8} {'ticks':>10}")
    for n in counts:
        with tempfile.TemporaryDirectory() as work:
            csv = os.path.join(work, "walk.csv")
            position = write_walk(csv, n)
            for plan_first in (True, False):
                r = run(binary, machine, csv, position, work, plan_first)
                mode = "--plan-first (before)" if plan_first else "while planning"
                if "error" in r:
                    print(f"{n:>8} {mode:<20} {r['error']}")
                else:
                    print(f"{n:>8} {mode:<20} {r['first_span_s']:>12.3f} {r['peak_rss_mb']:>11.1f} "
                          f"{r['wall_s']:>8.1f} {r['ticks']:>10}", flush=True)


if __name__ == "__main__":
    main()
