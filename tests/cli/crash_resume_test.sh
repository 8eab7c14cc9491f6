#!/usr/bin/env bash
# A host crash at any moment of a default stream (planning while streaming) is resumable, every
# drawn tick drawn once: `pathstream stream` is killed (SIGKILL) at seeded moments, half of them
# in the first second (planning still behind the device), `stream --resume` continues, and the
# device's record of path ticks is compared with the plan tick for tick (positions and pen).
# A random-walk B-spline long enough that the device, 30 times faster than real time, catches
# up with the planner; at least a quarter of the kills must find the plan incomplete, so the
# replanning path is exercised, not skipped.
#   crash_resume_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR [KILLS] [SEED]
set -u
bin=$1 src=$2 work=$3 kills=${4:-${PATHSTREAM_CRASH_KILLS:-20}} seed=${5:-20261128}
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
machine=$src/examples/machines/pen_plotter.json
failures=0 passed=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
ok() { passed=$((passed + 1)); }
py=/usr/bin/python3

# The drawing: one open B-spline of 5,000 control points, a seeded walk of 1.5 mm steps inside
# the plotter's area, starting at (100, 100).
$py - "$seed" > walk.json <<'EOF'
import json, math, random, sys
r = random.Random(int(sys.argv[1]))
x, y, a, pts = 100.0, 100.0, 0.0, []
for _ in range(5000):
    pts.append([round(x, 3), round(y, 3)])
    a += r.uniform(-1.2, 1.2)
    x = min(180.0, max(20.0, x + 1.5 * math.cos(a)))
    y = min(180.0, max(20.0, y + 1.5 * math.sin(a)))
json.dump({"basis": "bspline", "subpaths": [{"points": pts}]}, sys.stdout)
EOF
# The reference: the same plan, ordered from the same start the stream reads from the device;
# how long planning takes here.
t0=$(date +%s.%N)
"$bin" plan walk.json -m "$machine" --order-start 100,100 --out plan.csv > plan.log 2>&1 || { cat plan.log; exit 1; }
planning=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')

device_pid=
start_device() {
  rm -f record.csv
  : > device.log  # not left to the child: the loop below would read the last device's address
  "$bin" device -m "$machine" --no-gpio --tcp 127.0.0.1:0 --position 100,100 --time-scale 30 \
    --record record.csv --exit-after 600 > device.log 2>&1 &
  device_pid=$!
  for _ in $(seq 200); do
    target=$(sed -n 's/.*serving \(modbus-tcp:[^ ]*\).*/\1/p' device.log)
    [ -n "$target" ] && return 0
    sleep 0.05
  done
  fail "device did not start: $(cat device.log)"; return 1
}
stop_device() {
  kill -INT "$device_pid" 2>/dev/null
  for _ in $(seq 600); do kill -0 "$device_pid" 2>/dev/null || break; sleep 0.05; done
  kill -KILL "$device_pid" 2>/dev/null
  wait "$device_pid" 2>/dev/null
}

# Compares the device's record with plan.csv; re-entry ticks of a resume that re-entered the
# drawing (the .plan's spans of origin -1) are taken out first.
compare() {
  $py - "$1" <<'EOF'
import sys
name = sys.argv[1]
mm = 0.001
plan = []
with open("plan.csv") as f:
    next(f)
    for line in f:
        c = line.rstrip("\n").split(",")
        plan.append((round(float(c[2]) / mm), round(float(c[3]) / mm), int(c[-1])))
rec = []
with open("record.csv") as f:
    next(f)
    for line in f:
        c = line.rstrip("\n").split(",")
        rec.append((int(c[1]), int(c[2]), int(c[-1])))
reentry, at = 0, None
try:
    with open("j.json.plan") as f:
        lines = f.read().splitlines()[2:]
    for line in lines:
        c = line.split()
        if int(c[0]) == -1:
            reentry += int(c[4])
        elif at is None:
            at = int(c[1])
except FileNotFoundError:
    pass
if reentry:
    rec = rec[:at] + rec[at + reentry:]
# plan.csv has ticks 0 .. N (N: the end point), the record the N path ticks 0 .. N - 1.
want = plan[:-1]
if len(rec) != len(want):
    print(f"FAIL {name}: {len(rec)} path ticks recorded (re-entry {reentry} taken out), plan {len(want)}")
    sys.exit(1)
for k, (a, b) in enumerate(zip(rec, want)):
    if a != b:
        print(f"FAIL {name}: tick {k + 1}: recorded {a}, plan {b}")
        sys.exit(1)
EOF
}

# An uninterrupted stream first: the baseline, and how long a whole stream takes here.
start_device || exit 1
t0=$(date +%s.%N)
"$bin" stream walk.json -m "$machine" -t "$target" --journal j.json > stream0.log 2>&1 || fail "uninterrupted stream: $(tail -n 5 stream0.log)"
whole=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')
stop_device
if out=$(compare "uninterrupted stream"); then ok; else fail "${out#FAIL }"; fi
rm -f j.json j.json.plan j.json.plan.partial j.json.input record.csv
echo "crash resume: planning takes $planning s, an uninterrupted stream $whole s"

RANDOM=$seed
incomplete=0
for run in $(seq "$kills"); do
  start_device || exit 1
  # Half the kills while planning runs (within half the planning time, at most 0.5 s, after the
  # journal appears), the rest anywhere in a whole stream's time from its start.
  span=$whole
  if [ $((run % 2)) -eq 1 ]; then span=$(awk -v p="$planning" 'BEGIN { print (p < 1 ? p / 2 : 0.5) }'); fi
  delay=$(awk -v r=$RANDOM -v s=$span 'BEGIN { printf "%.3f", s * r / 32767 }')
  "$bin" stream walk.json -m "$machine" -t "$target" --journal j.json > stream1.log 2>&1 &
  stream_pid=$!
  if [ $((run % 2)) -eq 1 ]; then
    # Counted from the journal's first appearance (the first batch is on its way), not from the
    # start: on a loaded machine the start can take longer than the whole delay, and a kill
    # before any journal would test nothing. Planning is then still running.
    for _ in $(seq 600); do [ -f j.json ] && break; kill -0 "$stream_pid" 2>/dev/null || break; sleep 0.01; done
    delay="$delay after the journal appeared"
  fi
  sleep "${delay%% *}"
  kill -KILL "$stream_pid" 2>/dev/null
  wait "$stream_pid" 2>/dev/null; rc=$?
  name="run $run, SIGKILL after $delay s"
  if [ ! -f j.json ]; then
    ok  # killed before the journal existed: nothing was sent
    stop_device
    continue
  fi
  plan_hash=$($py -c 'import json,sys; print(json.load(open(sys.argv[1]))["plan_hash"])' j.json)
  [ -z "$plan_hash" ] && incomplete=$((incomplete + 1))
  if [ $rc -eq 0 ]; then
    ok
  else
    timeout -k 5 300 "$bin" stream --resume j.json > stream2.log 2>&1; rc=$?
    if [ $rc -eq 0 ]; then ok; else fail "$name: resume exit $rc: $(tail -n 5 stream2.log)"; fi
  fi
  stop_device
  if out=$(compare "$name"); then ok; else fail "${out#FAIL }"; fi
  rm -f j.json j.json.plan j.json.plan.partial j.json.input record.csv
done
echo "crash resume: $kills kills, $incomplete with the plan incomplete at the kill"
[ "$incomplete" -ge $((kills / 4)) ] && ok || fail "only $incomplete of $kills kills found the plan incomplete"
echo "crash resume: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
