#!/usr/bin/env bash
# Long jobs through the commands: `pathstream plan` of a 200,000-point B-spline and of a
# slow G-code job (400 moves at F10 mm/min: millions of ticks) under an address-space ceiling
# the whole-job planner needed several times over; an interrupted `plan -o` (SIGINT, SIGTERM)
# leaves neither the output nor its temporary file.
#   long_job_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
# PATHSTREAM_SANITIZED=1 skips the ceilings (sanitizers reserve terabytes of address space).
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
ok() { passed=$((passed + 1)); }
machine=$src/examples/machines/pen_plotter.json

/usr/bin/python3 - "$work" <<'PY'
import json, math, random, sys
work = sys.argv[1]
rng = random.Random(2026)
x = y = h = 0.0
points = []
for _ in range(200000):  # a random walk of 1.5 mm steps, kept inside a 200 mm square
    points.append([round(x, 4), round(y, 4)])
    h += rng.gauss(0, 0.25)
    x += 1.5 * math.cos(h)
    y += 1.5 * math.sin(h)
    if abs(x) > 100 or abs(y) > 100:
        h = math.atan2(-y, -x)
json.dump({"basis": "bspline", "points": points}, open(work + "/walk.json", "w"))
lines = ["G21 G90", "G0 X50 Y50", "G1 Z-1 F100", "F10"]
x, y = 50.0, 50.0
for i in range(400):  # 2 mm moves that turn a little: about 4.8 million ticks at 10 mm/min
    h += rng.gauss(0, 0.6)
    x = min(max(x + 2 * math.cos(h), 5), 180)
    y = min(max(y + 2 * math.sin(h), 5), 180)
    lines.append("G1 X%.3f Y%.3f" % (x, y))
lines += ["G0 Z5", "M2"]
open(work + "/slow.ngc", "w").write("\n".join(lines) + "\n")
PY

# 128 MB of address space: the job itself needs about 60 MB; the whole-job planner held
# about 1 KB per point (200 MB for the walk) and every span of the slow job (over 300 MB).
if [ -z "${PATHSTREAM_SANITIZED:-}" ]; then
  for job in walk.json slow.ngc; do
    out=$(ulimit -v 131072; "$bin" plan "$job" -m "$machine" 2>&1); rc=$?
    [ $rc -eq 0 ] && [[ "$out" == *"within limits"* ]] && ok || fail "plan $job under 128 MB: $rc $out"
  done
else
  echo "skipped: the address-space ceilings (sanitized build)"
fi

# An interrupted plan -o: started with the signal's default action (a background job of a
# script ignores SIGINT), stopped while it writes; no output, no temporary file.
for signal in INT TERM; do
  rm -f "$work"/out.csv*
  /usr/bin/python3 - "$bin" "$machine" "$signal" "$work" <<'PY'
import glob, signal, subprocess, sys, time
binary, machine, name, work = sys.argv[1:]
sig = getattr(signal, "SIG" + name)
child = subprocess.Popen([binary, "plan", work + "/slow.ngc", "-m", machine, "-o", work + "/out.csv"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                         preexec_fn=lambda: signal.signal(sig, signal.SIG_DFL))
for _ in range(400):  # the temporary file appears once the job is loaded and checked
    if glob.glob(work + "/out.csv.tmp-*") or child.poll() is not None:
        break
    time.sleep(0.01)
child.send_signal(sig)
sys.exit(0 if child.wait() == -sig else 1)
PY
  rc=$?
  left=$(ls "$work"/out.csv* 2>/dev/null)
  [ $rc -eq 0 ] && [ -z "$left" ] && ok || fail "plan -o stopped by SIG$signal: exit check $rc, left: $left"
done

echo "long_job_test: $passed passed, $failures failed"
[ $failures -eq 0 ]
