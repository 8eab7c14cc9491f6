#!/usr/bin/env bash
# Machine-readable events (docs/events.md) with the real binaries: `sim --events`, `stream
# --events` to `pathstream device --log-json` over Modbus TCP (a full run and a run held by
# SIGINT), and the device's text log. Every event line must validate against
# docs/events.schema.json (the device's lines against its $defs/device_log_line); job_start
# comes first and job_end last, progress events keep to --events-rate, and a full run enters
# subpaths 1..N in order.
#   events_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
machine=$src/examples/machines/pen_plotter.json
schema=$src/docs/events.schema.json
failures=0 passed=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
ok() { passed=$((passed + 1)); }
device_pid=

/usr/bin/python3 -c 'import jsonschema' 2>/dev/null || { echo "FAIL: python3-jsonschema is missing (scripts/setup.sh)"; exit 1; }

# check_events FILE KIND RATE OUTCOME [full]: validates every line of FILE and the order of
# the events; KIND sim paces progress by sim_t, stream by t.
check_events() {
  /usr/bin/python3 - "$schema" "$@" <<'PY'
import json, sys
import jsonschema
schema_path, path, kind, rate, outcome = sys.argv[1:6]
full = len(sys.argv) > 6 and sys.argv[6] == "full"
validator = jsonschema.Draft202012Validator(json.load(open(schema_path)))
errors = []
events = []
for number, line in enumerate(open(path), 1):
    try:
        e = json.loads(line)
        validator.validate(e)
        events.append(e)
    except (ValueError, jsonschema.ValidationError) as x:
        errors.append(f"line {number}: {str(x).splitlines()[0]}: {line.strip()[:200]}")
kinds = [e["event"] for e in events]
if not events or kinds[0] != "job_start" or kinds[-1] != "job_end":
    errors.append(f"not job_start ... job_end: {kinds[:3]} ... {kinds[-3:]}")
if kinds.count("job_start") != 1 or kinds.count("job_end") != 1:
    errors.append("job_start and job_end must come once each")
ts = [e["t"] for e in events]
if ts != sorted(ts):
    errors.append("t goes backwards")
clock = "sim_t" if kind == "sim" else "t"
progress = [e[clock] for e in events if e["event"] == "progress"]
if not progress:
    errors.append("no progress event")
gaps = [b - a for a, b in zip(progress, progress[1:])]
if gaps and min(gaps) < 1 / float(rate) - 1e-9:
    errors.append(f"progress events {min(gaps):.6f} s apart, rate bound {rate}/s")
if events and events[-1].get("outcome") != outcome:
    errors.append(f"outcome {events[-1].get('outcome')}, want {outcome}")
pens = [e["down"] for e in events if e["event"] == "pen"]
if any(a == b for a, b in zip(pens, pens[1:])) or (pens and not pens[0]):
    errors.append(f"pen events do not alternate from down: {pens}")
if kind == "stream" and "state" not in kinds:
    errors.append("no state event")
if outcome == "held" and "hold" not in kinds:
    errors.append("held without a hold event")
if full and events:
    start, end = events[0], events[-1]
    subpaths = [e["n"] for e in events if e["event"] == "subpath"]
    if subpaths != list(range(1, start["subpaths"] + 1)):
        errors.append(f"subpaths {subpaths}, want 1..{start['subpaths']}")
    # A stream planned as it goes knows its length by the end (job_start: null until then).
    if end["ticks"] != end["plan_ticks"]:
        errors.append(f"job_end ticks {end['ticks']}, plan {end['plan_ticks']}")
    if start["plan_ticks"] is not None and start["plan_ticks"] != end["plan_ticks"]:
        errors.append(f"job_start plan_ticks {start['plan_ticks']}, job_end {end['plan_ticks']}")
for x in errors:
    print(f"{path}: {x}")
sys.exit(1 if errors else 0)
PY
}

# check_device_log FILE: every line a device_log_line; the stream's job started and ended.
check_device_log() {
  /usr/bin/python3 - "$schema" "$1" <<'PY'
import json, sys
import jsonschema
schema = json.load(open(sys.argv[1]))
validator = jsonschema.Draft202012Validator({"$defs": schema["$defs"], "$ref": "#/$defs/device_log_line"})
errors, kinds = [], []
for number, line in enumerate(open(sys.argv[2]), 1):
    try:
        e = json.loads(line)
        validator.validate(e)
        kinds.append(e["event"])
    except (ValueError, jsonschema.ValidationError) as x:
        errors.append(f"line {number}: {str(x).splitlines()[0]}: {line.strip()[:200]}")
for want in ["serving", "connect", "state", "job_start", "job_end", "disconnect", "stopped"]:
    if want not in kinds:
        errors.append(f"no {want} line")
for x in errors:
    print(f"{sys.argv[2]}: {x}")
sys.exit(1 if errors else 0)
PY
}

# Starts the simulated device (--log-json) at rose.json's start on a free port; sets $target. The
# streams below pass --keep-order: the device rests at the file's first point, which ordering moves.
start_device() {
  "$bin" device -m "$machine" --no-gpio --tcp 127.0.0.1:0 --position 139.322,100 --time-scale 4 \
    --exit-after 120 --log-json > "$work/$1.ndjson" 2> "$work/$1.err" &
  device_pid=$!
  for _ in $(seq 100); do
    target=$(sed -n 's/.*"url":"\(modbus-tcp:[^"]*\)".*/\1/p' "$work/$1.ndjson")
    [ -n "$target" ] && return 0
    sleep 0.05
  done
  fail "device did not start: $(cat "$work/$1.ndjson" "$work/$1.err")"; return 1
}
# Waits (up to 60 s) until the device at $target runs: planning may take long (sanitizers).
wait_running() {
  for _ in $(seq 1200); do
    "$bin" ctl "$target" status --json 2>/dev/null | grep -q '"state": "running"' && return 0
    sleep 0.05
  done
  fail "the device never ran"; return 1
}
stop_device() { kill -INT "$device_pid" 2>/dev/null; wait "$device_pid" 2>/dev/null; }

# ---- sim: events on standard output, the report on standard error -------------------------
"$bin" sim "$src/examples/wave.json" -m "$machine" --events - > sim.ndjson 2> sim.err; rc=$?
[ $rc -eq 0 ] && ok || fail "sim --events -: exit $rc: $(cat sim.err)"
grep -q "pathstream run on the simulated device" sim.err && ok || fail "sim: the text report is not on stderr"
check_events sim.ndjson sim 5 finished full && ok || fail "sim wave.json events"
"$bin" sim "$src/examples/rose.json" -m "$machine" --plant ideal --events rose.ndjson --events-rate 2 > rose.out 2>&1; rc=$?
[ $rc -eq 0 ] && grep -q "pathstream run on the simulated device" rose.out && ok || fail "sim --events FILE: exit $rc"
check_events rose.ndjson sim 2 finished full && ok || fail "sim rose.json events (2 subpaths, 2 per s)"
out=$("$bin" sim "$src/examples/wave.json" -m "$machine" --json --events - 2>&1); rc=$?
[ $rc -eq 2 ] && ok || fail "sim --json --events -: exit $rc (want 2): $out"
out=$("$bin" sim "$src/examples/wave.json" -m "$machine" --events "$work/no/such/dir/e.ndjson" 2>&1); rc=$?
[ $rc -eq 3 ] && [[ "$out" == *"cannot write"* ]] && ok || fail "sim --events into a missing directory: exit $rc: $out"

# ---- stream: a full run, events on standard output ----------------------------------------
start_device device1 || exit 1
"$bin" stream "$src/examples/rose.json" --keep-order -m "$machine" -t "$target" --no-journal --events - \
  > stream1.ndjson 2> stream1.err; rc=$?
[ $rc -eq 0 ] && ok || fail "stream --events -: exit $rc: $(cat stream1.err)"
grep -q "^job           1 finished" stream1.err && ok || fail "stream: the text report is not on stderr"
check_events stream1.ndjson stream 5 finished full && ok || fail "stream full run events"
# A client that connects and leaves in a loop: at most 20 connection lines in a 10 s window.
/usr/bin/python3 - "$target" <<'PY'
import socket, sys
host, port = sys.argv[1].split("//")[1].split("?")[0].rsplit(":", 1)
for _ in range(200):
    socket.create_connection((host, int(port))).close()
PY
for _ in $(seq 100); do [ "$(grep -c '"event":"disconnect"' "$work/device1.ndjson")" -ge 10 ] && break; sleep 0.05; done
stop_device
check_device_log device1.ndjson && ok || fail "device --log-json lines"
# At most 20 lines in each 10 s window the device ran through (however slow the machine), far
# fewer than the 400 the loop's connections would write one by one.
/usr/bin/python3 - "$work/device1.ndjson" <<'PY' && ok || fail "the connection lines are not rate-limited"
import datetime, json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
t = [datetime.datetime.fromisoformat(l["time"].replace("Z", "+00:00")) for l in lines]
windows = int((t[-1] - t[0]).total_seconds() // 10) + 1
one_by_one = sum(l["event"] in ("connect", "disconnect") for l in lines)
counted = sum(l.get("connected", 0) + l.get("disconnected", 0) for l in lines if l["event"] == "connections")
print(f"connection lines {one_by_one} in {windows} windows; {counted} counted in summaries")
# Every connection is either a line or counted (the device says the last count as it stops).
sys.exit(0 if one_by_one <= 20 * windows and counted > 0 and one_by_one + counted >= 400 else 1)
PY

# ---- stream: Ctrl-C mid-stream holds the job -----------------------------------------------
start_device device2 || exit 1
"$bin" stream "$src/examples/rose.json" --keep-order -m "$machine" -t "$target" --journal "$work/j.json" \
  --events stream2.ndjson --events-rate 10 > stream2.log 2>&1 &
stream_pid=$!
wait_running
sleep 0.5
kill -INT "$stream_pid"
wait "$stream_pid"; rc=$?
[ $rc -eq 7 ] && ok || fail "stream interrupted: exit $rc (want 7): $(cat stream2.log)"
check_events stream2.ndjson stream 10 held && ok || fail "stream held run events"
stop_device

# ---- device: the text log is timestamped, one line each ------------------------------------
"$bin" device --tcp 127.0.0.1:0 --exit-after 0.2 > device3.log 2>&1
if [ "$(grep -cvE '^[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9]{2}:[0-9]{2}:[0-9]{2}\.[0-9]{3}Z pathstream device: ' device3.log)" -eq 0 ] &&
  grep -q "serving modbus-tcp://" device3.log; then ok; else fail "device text log: $(cat device3.log)"; fi

echo "events: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
