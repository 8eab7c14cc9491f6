#!/usr/bin/env bash
# The router examples end to end: each LinuxCNC-style program in examples/cnc plans within the
# router profile's limits, simulates, and streams to `pathstream device` serving the 3-axis
# profile over Modbus TCP, its M6 tool-change pauses resumed by `ctl resume`; the device must
# refuse nothing and end at the program's last point.
#   cnc_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
ok() { passed=$((passed + 1)); }
machine=$src/examples/machines/router.json
tools=(--tool-table "$src/examples/cnc/tools.tbl")

for name in pocket drill profile finish; do
  program=$src/examples/cnc/$name.ngc
  out=$("$bin" plan "$program" -m "$machine" "${tools[@]}" 2>&1); rc=$?
  [ $rc -eq 0 ] && [[ "$out" == *"within limits"* && "$out" == *"pause for the operator"* &&
    "$out" == *"spindle: on"*"1 starts (spin-up 2 s)"* ]] && ok ||
    fail "plan $name: $rc $out"
  out=$("$bin" sim "$program" -m "$machine" "${tools[@]}" --plot "$work/$name" --json 2>/dev/null); rc=$?
  [ $rc -eq 0 ] && [ -s "$work/$name/path.svg" ] && [ -s "$work/$name/z.svg" ] && ok ||
    fail "sim $name: $rc $out"
  echo "$out" | /usr/bin/python3 -c '
import json, sys
d = json.load(sys.stdin)
assert d["machine"]["axes"] == 3, d["machine"]
' 2>/dev/null && ok || fail "sim $name --json: not three axes: $(echo "$out" | head -c 300)"
done

# Streams: the device starts at the machine's origin; the job leads in from there.
scale=(pocket 20 drill 20 profile 20 finish 30)
for i in 0 2 4 6; do
  name=${scale[$i]}
  : > "$work/device.log"
  "$bin" device -m "$machine" --no-gpio --tcp 127.0.0.1:0 --time-scale "${scale[$((i + 1))]}" \
    --exit-after 300 > "$work/device.log" 2>&1 &
  device_pid=$!
  target=
  for _ in $(seq 200); do
    target=$(sed -n 's/.*serving \(modbus-tcp:[^ ]*\).*/\1/p' "$work/device.log")
    [ -n "$target" ] && break
    sleep 0.05
  done
  if [ -z "$target" ]; then
    fail "device did not start: $(cat "$work/device.log")"
    kill "$device_pid" 2>/dev/null; wait "$device_pid" 2>/dev/null
    continue
  fi
  "$bin" stream "$src/examples/cnc/$name.ngc" -m "$machine" "${tools[@]}" -t "$target" --no-journal \
    < /dev/null > "$work/stream_$name.log" 2>&1 &
  stream_pid=$!
  resumed=0 spindle=0 flood=0
  for _ in $(seq 2400); do
    kill -0 "$stream_pid" 2>/dev/null || break
    status=$("$bin" ctl "$target" status --json 2>/dev/null)
    grep -q '"spindle": "clockwise"' <<<"$status" && spindle=$((spindle + 1))
    grep -q '"flood": true' <<<"$status" && flood=$((flood + 1))
    if grep -q '"paused": true' <<<"$status"; then
      # A tool change stops the spindle before its pause.
      grep -q '"spindle": "off"' <<<"$status" && ok || fail "stream $name: the spindle runs in a tool change"
      # The operator reads the message first (the stream notices the pause on its next poll).
      for _ in $(seq 100); do
        grep -q "paused for" "$work/stream_$name.log" && break
        sleep 0.05
      done
      "$bin" ctl "$target" resume > /dev/null 2>&1 && resumed=$((resumed + 1))
    fi
    sleep 0.05
  done
  if kill -0 "$stream_pid" 2>/dev/null; then
    fail "stream $name did not end within 120 s: $(tail -n 5 "$work/stream_$name.log")"
    kill -KILL "$stream_pid" 2>/dev/null
  fi
  wait "$stream_pid"; rc=$?
  [ $rc -eq 0 ] && grep -q "finished: the device is idle at the drawing's end point" "$work/stream_$name.log" &&
    ok || fail "stream $name: exit $rc: $(tail -n 8 "$work/stream_$name.log")"
  [ "$resumed" -ge 1 ] && grep -q "paused for tool change to T" "$work/stream_$name.log" && ok ||
    fail "stream $name: no tool-change pause resumed ($resumed): $(grep -i paus "$work/stream_$name.log")"
  # M3 ran the spindle (and M8 the drill's flood coolant) on the device; the job's end stops them.
  [ "$spindle" -ge 1 ] && ok || fail "stream $name: the device never showed the spindle on"
  if [ "$name" = drill ]; then [ "$flood" -ge 1 ] && ok || fail "stream drill: no flood coolant seen"; fi
  status=$("$bin" ctl "$target" status --json 2>/dev/null)
  grep -q '"spindle": "off"' <<<"$status" && grep -q '"flood": false' <<<"$status" && ok ||
    fail "stream $name: outputs still on after the job: $status"
  kill -INT "$device_pid" 2>/dev/null; wait "$device_pid" 2>/dev/null
  grep -q "(0 refused)" "$work/device.log" && ok || fail "the device refused requests ($name): $(tail -5 "$work/device.log")"
done

echo "cnc: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
