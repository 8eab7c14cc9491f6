#!/usr/bin/env bash
# The STM32F405 firmware image under qemu (-M netduinoplus2), driven by the real host over
# Modbus RTU on a pseudo-terminal, as a user would drive a board on a serial port:
#   1. `ctl status` names the protocol and the axes; `ctl position` sets the start;
#   2. `stream examples/rose.json` draws the whole job: the image's tick trace (USART2) equals
#      the plan tick for tick, positions and pen;
#   3. a second job in a row (examples/wave.json, with its lead-in): the trace of both jobs
#      equals the record of `pathstream device` (the Linux device) driven the same way over
#      its own RTU pseudo-terminal; `ctl status --json` and a third-party master (mbpoll:
#      the status block and the configuration) read the same from both;
#   4. a job held by Ctrl-C, seen holding by `ctl status`, ends finished with `stream --resume`;
#   5. `ctl jog` moves exactly its distance through a `ctl hold` and `ctl resume`; a jog
#      stopped by `ctl stop` leaves the device idle;
#   6. the image's step/dir generator made, per axis, as many net steps as the setpoints moved
#      (the start position set by `ctl position` moved no axis and made no step).
#   qemu_stream_test.sh QEMU IMAGE PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
qemu=$1 image=$2 bin=$3 src=$4 work=$5
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
machine=$src/examples/machines/pen_plotter.json
py=/usr/bin/python3
failures=0 passed=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
ok() { passed=$((passed + 1)); }
qemu_pid= device_pid=
cleanup() {
  [ -n "$qemu_pid" ] && kill "$qemu_pid" 2>/dev/null
  [ -n "$device_pid" ] && kill -INT "$device_pid" 2>/dev/null
  wait 2>/dev/null
}
trap cleanup EXIT

# --- the image under qemu: USART1 on a new pty (the Modbus line), USART2 into trace.txt ------
"$qemu" -M netduinoplus2 -display none -monitor none -kernel "$image" \
  -serial pty -serial file:trace.txt > qemu.log 2>&1 &
qemu_pid=$!
for _ in $(seq 200); do
  pty=$(sed -n 's/.*redirected to \(\/dev\/pts\/[0-9]*\).*/\1/p' qemu.log | head -n 1)
  [ -n "$pty" ] && break
  sleep 0.05
done
[ -n "$pty" ] || { echo "FAIL qemu did not start: $(cat qemu.log)"; exit 1; }
# Held open for the whole test: qemu polls a pty nobody has open only once a second, so the
# first request of every new client would wait up to a second (and time out) otherwise. A
# board's serial port has no such pause. Nothing reads or writes on this descriptor.
exec 3<>"$pty"
sleep 1.2  # until qemu's once-a-second poll has seen it open
fw="modbus-rtu://$pty?baud=115200"  # the image's line: 8E1, unit 1

# --- the Linux device, the same machine, on its own RTU pty ------------------------------------
: > device.log
"$bin" device -m "$machine" --no-gpio --rtu-pty --record linux.csv \
  --exit-after 280 > device.log 2>&1 &
device_pid=$!
for _ in $(seq 200); do
  linux=$(sed -n 's/.*serving \(modbus-rtu:[^ ]*\).*/\1/p' device.log)
  [ -n "$linux" ] && break
  sleep 0.05
done
[ -n "$linux" ] || { echo "FAIL the Linux device did not start: $(cat device.log)"; exit 1; }

# The path ticks of a trace or a record ("k,x,y,pen" lines; '#' notes and the header skipped),
# for the comparisons below.
cat > trace_rows.py <<'EOF'
def rows(name):
    out = []
    with open(name) as f:
        for line in f:
            if line.startswith("#") or line.startswith("tick"):
                continue
            c = line.rstrip("\n").split(",")
            out.append((int(c[1]), int(c[2]), int(c[3])))
    return out
EOF

# Runs a command with a bound; a hang is a failure with its output, not a slow machine.
run() { timeout -k 5 120 "$@"; }

# 1. Status and the start position, on both devices.
for target in "$fw" "$linux"; do
  if out=$(run "$bin" ctl "$target" status 2>&1) && grep -q "protocol 6, 2 axes" <<<"$out"; then
    ok
  else
    fail "ctl status on $target: $out"
  fi
  for axis in x y; do
    run "$bin" ctl -m "$machine" "$target" position "$axis" 50 > position.log 2>&1 ||
      fail "ctl position $axis 50 on $target: $(cat position.log)"
  done
done

# 2 and 3. Two jobs in a row on both: rose from its start point (no lead-in), wave after it.
# Both side by side in real time; planned first, so that nothing but the link paces a stream.
stream_both() {  # NAME DRAWING
  run "$bin" stream "$2" -m "$machine" -t "$fw" --no-journal --plan-first > "fw-$1.log" 2>&1 &
  local fw_pid=$!
  run "$bin" stream "$2" -m "$machine" -t "$linux" --no-journal --plan-first > "linux-$1.log" 2>&1 || fail "stream $1 to the Linux device: $(tail -n 5 "linux-$1.log")"
  wait "$fw_pid" || fail "stream $1 to the firmware: $(tail -n 8 "fw-$1.log")"
  grep -q "finished: the device is idle at the drawing's end point" "fw-$1.log" && ok ||
    fail "stream $1 to the firmware did not finish: $(tail -n 8 "fw-$1.log")"
}
stream_both rose "$src/examples/rose.json"
stream_both wave "$src/examples/wave.json"
run "$bin" ctl "$fw" status --json > fw-status.json 2>&1 || fail "ctl status --json: $(cat fw-status.json)"
run "$bin" ctl "$linux" status --json > linux-status.json 2>&1 || fail "ctl status --json (Linux)"

# A third-party master (Debian's mbpoll, libmodbus-based) reads the status block (FC4 0..49)
# and the configuration (FC3 110..139) from both: the same registers, the same values.
mbpoll_read() {  # MBPOLL_ARGS... DEVICE_PATH: "REGISTER VALUE" lines
  timeout -k 2 20 mbpoll -m rtu -b 115200 -P even -a 1 -o 2 -1 "$@" 2>&1 | sed -n 's/^\[\([0-9]*\)\]:[[:space:]]*\(-*[0-9]*\).*/\1 \2/p'
}
linux_pty=${linux#modbus-rtu://}; linux_pty=${linux_pty%%\?*}
for block in "-t 3 -r 1 -c 50" "-t 4 -r 111 -c 30"; do
  # shellcheck disable=SC2086 # the block's words are mbpoll arguments
  # Register 27 counts underruns: the link's timing, not the device (see the JSON below).
  fw_regs=$(mbpoll_read $block "$pty" | grep -v '^28 ')
  # shellcheck disable=SC2086
  linux_regs=$(mbpoll_read $block "$linux_pty" | grep -v '^28 ')
  if [ -n "$fw_regs" ] && [ "$fw_regs" = "$linux_regs" ]; then
    ok
  else
    fail "mbpoll $block: firmware and Linux device differ: $(diff <(echo "$fw_regs") <(echo "$linux_regs") | head -n 6 | tr '\n' ' ')"
  fi
done

# The plan of the first job, from the start point the devices were set to.
run "$bin" plan "$src/examples/rose.json" -m "$machine" --order-start 50,50 --out rose-plan.csv \
  > plan.log 2>&1 || fail "plan: $(tail -n 5 plan.log)"

# The firmware writes its trace as the ticks come; wait for the steps note that follows a job.
for _ in $(seq 100); do grep -q "^# steps y" trace.txt && break; sleep 0.05; done
if out=$($py - <<'EOF'
import json, sys
from trace_rows import rows
fw = rows("trace.txt")
plan = []
with open("rose-plan.csv") as f:
    next(f)
    for line in f:
        c = line.rstrip("\n").split(",")
        plan.append((round(float(c[2]) / 0.001), round(float(c[3]) / 0.001), int(c[-1])))
plan = plan[:-1]  # ticks 0 .. N - 1 are path ticks; N is the end point
errors = []
if fw[:len(plan)] != plan:
    k = next(i for i, (a, b) in enumerate(zip(fw + [None] * len(plan), plan)) if a != b)
    errors.append(f"rose: trace tick {k} is {fw[k] if k < len(fw) else 'missing'}, plan {plan[k]}")
# The Linux device's record after the device exits: compared below, when it has been written.
with open("fw_ticks.txt", "w") as f:
    f.write(f"{len(plan)} {len(fw)}\n")
fs = json.load(open("fw-status.json"))
ls = json.load(open("linux-status.json"))
# The target differs by name; the underrun count by the link's timing (a stall of qemu under
# load runs the queue dry; the device stops and comes back onto the path, whose ticks stay
# the plan's: the trace comparisons above and below hold either way).
for d in (fs, ls):
    d.pop("target", None)
    d.pop("underruns", None)
if fs != ls:
    keys = sorted(k for k in set(fs) | set(ls) if fs.get(k) != ls.get(k))
    errors.append("ctl status --json differs: " + ", ".join(f"{k}: {fs.get(k)} / {ls.get(k)}" for k in keys))
print("\n".join(errors))
sys.exit(1 if errors else 0)
EOF
); then ok; else fail "$out"; fi
read -r plan_ticks two_job_ticks < fw_ticks.txt
echo "firmware: rose $plan_ticks path ticks equal the plan; rose and wave $two_job_ticks path ticks"

# An RTU line has one master: `ctl` talks to the image only while no stream does (on a pty, a
# second master would read the first one's answers).
state() { run "$bin" ctl "$fw" status --json 2>/dev/null | $py -c 'import json,sys; print(json.load(sys.stdin)["state"])'; }
wait_state() {  # STATE: up to 20 s
  for _ in $(seq 200); do [ "$(state)" = "$1" ] && return 0; sleep 0.1; done
  return 1
}
x_of() { run "$bin" ctl -m "$machine" "$fw" status --json | $py -c 'import json,sys; print(json.load(sys.stdin)["position"][0]["position_lsb"])'; }

# 4. A job held by Ctrl-C (the stream holds the device and exits 7), seen holding by `ctl
# status`, then continued by `stream --resume` to its end.
$py - > loop.json <<'EOF2'
import json, math
pts = [[100 + 40 * math.cos(k * 0.35) + 5 * math.sin(k * 1.3), 100 + 40 * math.sin(k * 0.35)] for k in range(40)]
json.dump({"basis": "bspline", "subpaths": [{"points": pts}]}, open(1, "w"))
EOF2
"$bin" stream loop.json -m "$machine" -t "$fw" --journal loop.journal.json --plan-first > fw-loop.log 2>&1 &
stream_pid=$!
# The journal is written when the first batch goes out; the job is then moving.
for _ in $(seq 400); do [ -f loop.journal.json ] && break; sleep 0.05; done
sleep 1.5
kill -INT "$stream_pid"
wait "$stream_pid"; rc=$?
[ $rc -eq 7 ] && ok || fail "Ctrl-C: stream exit $rc, not 7: $(tail -n 8 fw-loop.log)"
[ "$(state)" = holding ] && ok || fail "after Ctrl-C the state is $(state), not holding"
run "$bin" stream --resume loop.journal.json > fw-loop2.log 2>&1 &&
  grep -q "finished: the device is idle at the drawing's end point" fw-loop2.log && ok ||
  fail "stream --resume after the hold: $(tail -n 8 fw-loop2.log)"

# 5. The device's own moves: a jog held and resumed by `ctl` ends exactly at its distance; a
# jog stopped by `ctl stop` leaves the device idle.
before=$(x_of)
run "$bin" ctl -m "$machine" "$fw" jog x -60 --feed 40 --wait 0 > jog.log 2>&1 || fail "ctl jog x -60: $(cat jog.log)"
sleep 0.3
out=$(run "$bin" ctl "$fw" hold 2>&1)
[[ "$out" == *"accepted: running -> holding"* ]] && ok || fail "ctl hold of the jog: $out"
[ "$(state)" = holding ] && ok || fail "after ctl hold the state is $(state)"
out=$(run "$bin" ctl "$fw" resume 2>&1)
[[ "$out" == *"accepted: holding -> running"* ]] && ok || fail "ctl resume of the jog: $out"
wait_state idle || fail "the resumed jog did not end: state $(state)"
after=$(x_of)
[ $((before - after)) -eq 60000 ] && ok || fail "the held and resumed jog x -60 moved x from $before to $after LSB"
run "$bin" ctl -m "$machine" "$fw" jog x 50 --feed 40 --wait 0 > jog2.log 2>&1 || fail "ctl jog x 50: $(cat jog2.log)"
sleep 0.3
out=$(run "$bin" ctl "$fw" stop 2>&1)
[[ "$out" == *"accepted: running -> idle"* || "$out" == *"-> idle"* ]] && ok || fail "ctl stop of the jog: $out"
[ "$(state)" = idle ] && ok || fail "after ctl stop the state is $(state)"
stopped=$(x_of)
[ "$stopped" -gt "$after" ] && [ "$stopped" -lt $((after + 50000)) ] && ok ||
  fail "the stopped jog x 50 moved x from $after to $stopped LSB"

# 6. Net steps per axis equal the distance moved: the step/dir generator ran on every tick.
sleep 0.3
if out=$($py - "$pty" <<'EOF'
import json, subprocess, sys
steps = {}
for line in open("trace.txt"):
    if line.startswith("# steps "):
        _, _, axis, value = line.split()
        steps[axis] = int(value)
print(steps)
EOF
); then
  # The start position (50, 50) was set, not moved to: it made no step.
  moved=$(run "$bin" ctl "$fw" status --json | $py -c 'import json,sys; d=json.load(sys.stdin); print({"x": d["position"][0]["position_lsb"] - 50000, "y": d["position"][1]["position_lsb"] - 50000})' 2>&1)
  [ "$out" = "$moved" ] && ok || fail "net steps $out, position moved since it was set $moved"
else
  fail "steps: $out"
fi
grep -q "^# trace_lost" trace.txt && fail "the trace lost records: $(grep '^# trace_lost' trace.txt | tail -n 1)"

# 3, the record half: the Linux device writes it when it exits.
kill -INT "$device_pid"; wait "$device_pid"; device_pid=
if out=$($py - "$two_job_ticks" <<'EOF'
import sys
from trace_rows import rows
n = int(sys.argv[1])
fw = rows("trace.txt")[:n]
lx = rows("linux.csv")
if fw != lx:
    k = next((i for i, (a, b) in enumerate(zip(fw, lx)) if a != b), min(len(fw), len(lx)))
    print(f"two jobs: firmware {len(fw)} path ticks, Linux device {len(lx)}; first difference at tick {k}")
    sys.exit(1)
EOF
); then ok; else fail "$out"; fi

echo "firmware under qemu: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
