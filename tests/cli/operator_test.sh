#!/usr/bin/env bash
# An operator's session with the real binaries over Modbus TCP: `pathstream device` serving,
# `pathstream stream` interrupted by SIGINT at seeded moments (one Ctrl-C: hold; two: stop) or
# killed (SIGKILL: the host dies, the device runs out its queue), `pathstream stream --resume`,
# and `pathstream ctl` status and commands (pen, jog, position, home refused without switches),
# and a two-layer drawing's pen-change pause resumed by `ctl resume`. Every run must end
# with the device idle at the drawing's end and exactly the plan's path ticks executed, pen
# down on exactly the plan's pen-down ticks (the device's record).
#   operator_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR [RUNS]
set -u
bin=$1 src=$2 work=$3 runs=${4:-${PATHSTREAM_OPERATOR_RUNS:-3}}
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
machine=$src/examples/machines/pen_plotter.json
drawing=$src/examples/rose.json
failures=0 passed=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
ok() { passed=$((passed + 1)); }
device_pid=

# Starts the simulated device at the drawing's start on a free port; sets $target.
start_device() {
  # Emptied here, not by the child's redirection: until the child runs, the loop below would
  # read the last device's address from the old log.
  : > "$work/device.log"
  "$bin" device -m "$machine" --no-gpio --tcp 127.0.0.1:0 --position 139.322,100 --time-scale "$1" \
    --record "$work/record.csv" --exit-after 300 > "$work/device.log" 2>&1 &
  device_pid=$!
  for _ in $(seq 100); do
    target=$(sed -n 's/.*serving \(modbus-tcp:[^ ]*\).*/\1/p' "$work/device.log")
    [ -n "$target" ] && return 0
    sleep 0.05
  done
  fail "device did not start: $(cat "$work/device.log")"; return 1
}
# Waits (up to 60 s) until the device at $target runs: planning may take long (sanitizers).
wait_running() {
  for _ in $(seq 1200); do
    "$bin" ctl "$target" status --json 2>/dev/null | grep -q '"state": "running"' && return 0
    sleep 0.05
  done
  fail "the device never ran"; return 1
}
# Waits (up to 120 s) for background process $1 and returns its exit status; one that does not
# end is a hang, not a slow machine: it is reported with the logs and killed (status 124).
finish() {
  local pid=$1 what=$2
  for _ in $(seq 2400); do
    kill -0 "$pid" 2>/dev/null || { wait "$pid"; return $?; }
    sleep 0.05
  done
  fail "$what did not end within 120 s; stream: $(tail -n 5 "$work/stream1.log" 2>/dev/null); device: $(tail -n 5 "$work/device.log")"
  kill -KILL "$pid" 2>/dev/null; wait "$pid" 2>/dev/null
  return 124
}
# Runs `pathstream stream --resume` with a bound (a hang fails the step with the logs).
resume() {
  timeout -k 5 120 "$bin" stream --resume "$work/j.json" > "$work/stream2.log" 2>&1; local rc=$?
  [ $rc -eq 124 ] && fail "stream --resume did not end within 120 s: $(tail -n 5 "$work/stream2.log"); device: $(tail -n 5 "$work/device.log")"
  return $rc
}
stop_device() { kill -INT "$device_pid" 2>/dev/null; finish "$device_pid" "the device after SIGINT"; }

# The plan's path ticks and pen-down ticks (the setpoints CSV: tick,...,pen columns).
"$bin" plan "$drawing" --keep-order -m "$machine" --out "$work/plan.csv" > /dev/null 2>&1 || fail "plan"
plan_ticks=$(($(wc -l < "$work/plan.csv") - 2))  # header and the end point
plan_pen=$(awk -F, 'NR > 1 { n += $NF } END { print n }' "$work/plan.csv")

# ---- ctl: status, refusals, a hold and a resume of a running stream -------------------
start_device 2 || exit 1
out=$("$bin" ctl "$target" status -m "$machine" 2>&1)
[[ "$out" == *"state         idle"* && "$out" == *"x 139.3220 mm (139322 LSB)"* ]] && ok || fail "ctl status: $out"
out=$("$bin" ctl "$target" status --json 2>&1)
echo "$out" | /usr/bin/python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["state"]=="idle" and d["position"][0]["position_lsb"]==139322 and d["protocol_version"]==6 and d["pen_down"] is False and d["spindle"]=="off" and d["flood"] is False and d["position"][0]["homing"]=="not homed"' && ok || fail "ctl status --json: $out"
out=$("$bin" ctl "$target" hold 2>&1); rc=$?
[ $rc -eq 6 ] && [[ "$out" == *"device refused hold while idle: command not allowed in this state"* ]] && ok || fail "ctl hold idle: $rc $out"
out=$("$bin" ctl "$target" jog x 5.5 --feed 20 -m "$machine" 2>&1)
[[ "$out" == *"jog           x by 5500 LSB: done in"* && "$out" == *"x 144.8220 mm"* ]] && ok || fail "ctl jog: $out"
out=$("$bin" ctl "$target" jog 0 -5500lsb 2>&1)
[[ "$out" == *"x 139322 LSB"* ]] && ok || fail "ctl jog back in LSB: $out"
out=$("$bin" ctl "$target" jog x 5 2>&1); rc=$?
[ $rc -eq 2 ] && [[ "$out" == *"no axis 'x'"* ]] && ok || fail "ctl jog by name without -m: $rc $out"
out=$("$bin" ctl "$target" jog x 5 --feed 1000 -m "$machine" 2>&1); rc=$?
[ $rc -eq 2 ] && [[ "$out" == *"above the axis's"* ]] && ok || fail "ctl jog too fast: $rc $out"
out=$("$bin" ctl "$target" position y 100.0004 -m "$machine" 2>&1); rc=$?
[ $rc -eq 2 ] && [[ "$out" == *"not a whole number of LSB"* ]] && ok || fail "ctl position not whole: $rc $out"
# The operator's pen: down at rest, carried by a jog (it draws), up again; home without
# switches is refused by name.
out=$("$bin" ctl "$target" pen down 2>&1)
[[ "$out" == *"pen           down"* ]] && ok || fail "ctl pen down: $out"
out=$("$bin" ctl "$target" jog y 2 -m "$machine" 2>&1)
out=$("$bin" ctl "$target" status --json 2>&1)
echo "$out" | /usr/bin/python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["pen_down"] is True and d["position"][1]["position_lsb"]==102000' && ok || fail "pen down after a jog: $out"
out=$("$bin" ctl "$target" pen up 2>&1)
[[ "$out" == *"pen           up"* ]] && ok || fail "ctl pen up: $out"
out=$("$bin" ctl "$target" pen sideways 2>&1); rc=$?
[ $rc -eq 2 ] && [[ "$out" == *"want up or down"* ]] && ok || fail "ctl pen sideways: $rc $out"
out=$("$bin" ctl "$target" home 2>&1); rc=$?
[ $rc -eq 6 ] && [[ "$out" == *"device refused home while idle: no homing switch for that axis"* ]] && ok || fail "ctl home without switches: $rc $out"
"$bin" ctl "$target" jog y -2 -m "$machine" > /dev/null 2>&1 || fail "jog y back"
out=$("$bin" ctl "$target" jump 2>&1); rc=$?
[ $rc -eq 2 ] && ok || fail "ctl bad verb: $rc $out"
out=$("$bin" ctl "modbus-tcp://127.0.0.1:1?unit=1" status --link-timeout 0.2 2>&1); rc=$?
[ $rc -eq 6 ] && [[ "$out" == *"cannot connect"* ]] && ok || fail "ctl dead target: $rc $out"
"$bin" stream "$drawing" --keep-order -m "$machine" -t "$target" --no-journal > "$work/stream0.log" 2>&1 &
stream_pid=$!
wait_running
out=$("$bin" ctl "$target" hold 2>&1)
[[ "$out" == *"accepted: running -> holding"* ]] && ok || fail "ctl hold: $out"
out=$("$bin" ctl "$target" status --watch 0.05 --count 3 2>&1)
[ "$(echo "$out" | grep -c '^holding')" -eq 3 ] && ok || fail "ctl status --watch: $out"
out=$("$bin" ctl "$target" resume 2>&1)
[[ "$out" == *"accepted: holding -> running"* ]] && ok || fail "ctl resume: $out"
wait "$stream_pid"; rc=$?
[ $rc -eq 0 ] && ok || fail "stream held and resumed by ctl: exit $rc: $(cat "$work/stream0.log")"
stop_device

# ---- A stop from ctl during a stream: reported as a stop (exit 7, the resume hint), resumable
start_device 2 || exit 1
"$bin" stream "$drawing" --keep-order -m "$machine" -t "$target" --journal "$work/js.json" > "$work/stream_stop.log" 2>&1 &
stream_pid=$!
wait_running
out=$("$bin" ctl "$target" stop 2>&1)
[[ "$out" == *"accepted"* ]] && ok || fail "ctl stop: $out"
finish "$stream_pid" "stream after ctl stop"; rc=$?
[ $rc -eq 7 ] && ok || fail "stream stopped by ctl: exit $rc (want 7): $(cat "$work/stream_stop.log")"
grep -q "^stopped       by another client" "$work/stream_stop.log" && ok || fail "no 'stopped by another client': $(cat "$work/stream_stop.log")"
grep -q "refused spans" "$work/stream_stop.log" && fail "a ctl stop reported as a refusal: $(cat "$work/stream_stop.log")" || ok
grep -q "resume with   pathstream stream --resume $work/js.json" "$work/stream_stop.log" && ok || fail "no resume hint after ctl stop"
timeout -k 5 120 "$bin" stream --resume "$work/js.json" > "$work/stream_stop2.log" 2>&1; rc=$?
[ $rc -eq 0 ] && ok || fail "resume after ctl stop: exit $rc: $(tail -n 5 "$work/stream_stop2.log")"
stop_device
rm -f "$work"/js.json*

# ---- The lead-in is the default; --no-lead-in refuses a device resting elsewhere (in mm) and
# leaves no file behind, as does every stream the device took nothing of.
start_device 20 || exit 1
out=$("$bin" stream "$src/examples/two_pens.svg" -m "$machine" -t "$target" --journal "$work/nl.json" \
  --no-lead-in --pause none < /dev/null 2>&1); rc=$?
[ $rc -eq 6 ] && [[ "$out" == *"device rests at x 139.3220 y 100.0000 mm (139322 100000 LSB) but the plan starts at x "* ]] &&
  [[ "$out" == *"journal       none kept: the device took nothing of this job"* ]] && ok ||
  fail "--no-lead-in away from the start: exit $rc: $out"
[ -z "$(ls "$work"/nl.json* 2>/dev/null)" ] && ok || fail "--no-lead-in left files: $(ls "$work"/nl.json*)"
out=$("$bin" stream "$src/examples/two_pens.svg" -m "$machine" -t "$target" --journal "$work/nl.json" \
  --pause none < /dev/null 2>&1); rc=$?
[ $rc -eq 0 ] && [[ "$out" == *"lead-in       pen up from where the device rests, x 139.3220 mm y 100.0000 mm, to the drawing's start"* ]] && ok ||
  fail "the default lead-in: exit $rc: $out"
[ -f "$work/nl.json" ] && [ -f "$work/nl.json.plan" ] && ok || fail "a finished stream kept no journal"
stop_device
rm -f "$work"/nl.json*

# ---- The default journal of a job the device may still hold is not replaced by a new stream
start_device 4 || exit 1
(cd "$work" && timeout -s INT 1.5 "$bin" stream "$src/examples/rose.json" -m "$machine" -t "$target" \
  < /dev/null > "$work/dj1.log" 2>&1); rc=$?
out=$(cd "$work" && "$bin" stream "$src/examples/rose.json" -m "$machine" -t "$target" < /dev/null 2>&1); rc2=$?
if grep -q "resume with" "$work/dj1.log"; then
  [ $rc2 -eq 2 ] && [[ "$out" == *"rose.journal.json: the journal of job 1"*"continue it with \`pathstream stream --resume rose.journal.json\`"* ]] &&
    ok || fail "a second stream replaced the journal of an interrupted job: exit $rc2: $out"
  # Named explicitly, the same journal is kept the same way.
  out=$(cd "$work" && "$bin" stream "$src/examples/rose.json" -m "$machine" -t "$target" --journal rose.journal.json < /dev/null 2>&1); rc2=$?
  [ $rc2 -eq 2 ] && [[ "$out" == *"give --replace-journal or another --journal"* ]] &&
    ok || fail "--journal replaced the journal of an interrupted job: exit $rc2: $out"
  (cd "$work" && timeout -k 5 120 "$bin" stream --resume rose.journal.json < /dev/null > "$work/dj2.log" 2>&1) &&
    ok || fail "resume of the kept journal: $(tail -n 5 "$work/dj2.log")"
else
  ok; ok; ok  # the drawing ended before the interrupt
fi
out=$(cd "$work" && "$bin" stream "$src/examples/rose.json" -m "$machine" -t "$target" < /dev/null 2>&1) &&
  ok || fail "a stream after the finished job: $out"
stop_device
rm -f "$work"/rose.journal.json*

# ---- Two layers: the device pauses pen up between them until `ctl resume` ---------------
start_device 2 || exit 1
"$bin" stream "$src/examples/two_pens.svg" -m "$machine" -t "$target" --no-journal --lead-in \
  --events "$work/pause.ndjson" < /dev/null > "$work/stream_pause.log" 2>&1 &
stream_pid=$!
paused=
for _ in $(seq 1200); do
  out=$("$bin" ctl "$target" status --json 2>/dev/null)
  echo "$out" | grep -q '"paused": true' && { paused=1; break; }
  sleep 0.05
done
[ -n "$paused" ] && ok || fail "the device never paused between the layers: $(cat "$work/stream_pause.log")"
echo "$out" | /usr/bin/python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["state"]=="holding" and d["pen_down"] is False' && ok || fail "paused: $out"
sleep 0.5
"$bin" ctl "$target" status --json | grep -q '"paused": true' && ok || fail "the pause ended without the operator"
grep -q 'paused for a pen change, layer "accent" next: go on with `pathstream ctl' "$work/stream_pause.log" && ok ||
  fail "no pause message: $(cat "$work/stream_pause.log")"
out=$("$bin" ctl "$target" resume 2>&1)
[[ "$out" == *"accepted: holding -> running"* ]] && ok || fail "ctl resume at the pause: $out"
wait "$stream_pid"; rc=$?
[ $rc -eq 0 ] && ok || fail "stream with a pause: exit $rc: $(cat "$work/stream_pause.log")"
grep -q '"event":"pause".*"next":"layer \\"accent\\""' "$work/pause.ndjson" && ok || fail "no pause event: $(cat "$work/pause.ndjson")"
stop_device

# ---- Ctrl-C (once, twice) or SIGKILL at seeded moments, then --resume --------------------
check_record() {  # the whole drawing's path ticks once: count and pen-down count
  local rows pen
  rows=$(($(wc -l < "$work/record.csv") - 1))
  pen=$(awk -F, 'NR > 1 { n += $NF } END { print n }' "$work/record.csv")
  # A stop resumes with a re-entry (path ticks of its own, pen up, and a pen-down approach
  # of whole spans): those come on top; a hold resumes on the device's own re-entry.
  # A stop acts inside a span, and --resume draws that span again from its start: up to one
  # span's ticks (`again`, the longest span of the plan) come twice.
  local extra_rows=$2 extra_pen=$3 again=${4:-0}
  local over=$((rows - plan_ticks - extra_rows)) over_pen=$((pen - plan_pen - extra_pen))
  if [ "$over" -ge 0 ] && [ "$over" -le "$again" ] && [ "$over_pen" -ge 0 ] && [ "$over_pen" -le "$over" ]; then ok
  else fail "$1: record has $rows path ticks ($pen pen down), plan $plan_ticks ($plan_pen) + $extra_rows ($extra_pen), up to $again again"; fi
}
RANDOM=20261125
for run in $(seq "$runs"); do
  for presses in 1 2 kill; do
    start_device 4 || exit 1
    delay=$(awk -v r=$RANDOM 'BEGIN { printf "%.2f", 3.0 * r / 32767 }')
    "$bin" stream "$drawing" --keep-order -m "$machine" -t "$target" --journal "$work/j.json" > "$work/stream1.log" 2>&1 &
    stream_pid=$!
    wait_running
    sleep "$delay"
    if [ "$presses" = kill ]; then
      kill -KILL "$stream_pid"  # the host dies: no hold, no journal update after this
    else
      kill -INT "$stream_pid"
      [ "$presses" = 2 ] && { sleep 0.001; kill -INT "$stream_pid" 2>/dev/null; }
    fi
    finish "$stream_pid" "stream after $presses"; rc=$?
    name="run $run, $presses Ctrl-C after $delay s"
    [ "$presses" = kill ] && name="run $run, SIGKILL after $delay s"
    outcome=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["outcome"])' "$work/j.json")
    if [ $rc -eq 7 ]; then
      [[ "$(cat "$work/stream1.log")" == *"resume with   pathstream stream --resume $work/j.json"* ]] && ok ||
        fail "$name: no resume hint: $(cat "$work/stream1.log")"
      st=$("$bin" ctl "$target" status --json | /usr/bin/python3 -c 'import json,sys; d=json.load(sys.stdin); print(d["state"])')
      want=holding; [ "$outcome" = stopped ] && want=idle
      [ "$st" = "$want" ] && ok || fail "$name: device $st after the interrupt (journal: $outcome)"
      resume; rc=$?
      [ $rc -eq 0 ] && ok || fail "$name: resume exit $rc: $(cat "$work/stream2.log")"
    elif [ $rc -eq 137 ]; then
      # Killed: the device runs out its queue and holds (or ends the job); --resume waits
      # for that, then streams the rest.
      resume; rc=$?
      [ $rc -eq 0 ] && ok || fail "$name: resume exit $rc: $(cat "$work/stream2.log")"
    elif [ $rc -eq 0 ]; then
      ok  # the drawing ended before the interrupt arrived
    else
      fail "$name: stream exit $rc: $(cat "$work/stream1.log")"
    fi
    outcome=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["outcome"])' "$work/j.json")
    [ "$outcome" = finished ] && ok || fail "$name: journal outcome $outcome"
    stop_device
    extra_rows=0 extra_pen=0
    if [ -f "$work/j.json.plan" ] && grep -q '^-1 ' "$work/j.json.plan"; then
      extra_rows=$(awk '$1 == -1 { n += $5 } END { print n + 0 }' "$work/j.json.plan")
      extra_pen=$(awk '$1 == -1 && $4 == 1 { n += $5 } END { print n + 0 }' "$work/j.json.plan")
    fi
    again=0
    if [ "$presses" = 2 ] && [ -f "$work/j.json.plan" ]; then
      again=$(awk '$1 ~ /^[0-9]+$/ && $5 + 0 > n { n = $5 + 0 } END { print n + 0 }' "$work/j.json.plan")
    fi
    check_record "$name" "$extra_rows" "$extra_pen" "$again"
    rm -f "$work/j.json" "$work/j.json.plan" "$work/record.csv"
  done
done
echo "operator: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
