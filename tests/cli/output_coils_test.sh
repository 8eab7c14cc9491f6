#!/usr/bin/env bash
# Output coils end to end: `pathstream device` serving the router profile with "output_coils"
# on a simulated Modbus I/O module (pathstream_coil_module: libmodbus's own server). The device
# writes every coil off before it serves and again when it stops (the module counts both
# writes and sees no change); a module that is not there, or that refuses a coil it does not
# have, stops the start with exit 6 and a message naming the profile, the target and the coil.
# Then drill.ngc streamed to the device turns the spindle and flood coils on after its tool
# change and off by its end (holds and faults: tests/device/test_output_coils.cpp).
#   output_coils_test.sh PATHSTREAM_BINARY COIL_MODULE_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 module_bin=$2 src=$3 work=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
ok() { passed=$((passed + 1)); }

# Starts the module with $2 coils, its output in $1; sets module_pid and port (empty if it did
# not start).
start_module() {
  "$module_bin" --coils "$2" --seconds 300 > "$work/$1" 2>&1 &
  module_pid=$!
  port=
  for _ in $(seq 200); do
    port=$(sed -n 's/^port \([0-9]*\)$/\1/p' "$work/$1")
    [ -n "$port" ] && break
    sleep 0.05
  done
}

# The router profile with its spindle on coil 0 and flood on coil 3 of the module at port $1.
write_profile() {
  /usr/bin/python3 - "$src/examples/machines/router.json" "$work/router_coils.json" "$1" <<'PY'
import json, sys
profile = json.load(open(sys.argv[1]))
profile["output_coils"] = {"target": "modbus-tcp://127.0.0.1:%s?unit=1" % sys.argv[3],
                           "spindle": 0, "flood": 3}
json.dump(profile, open(sys.argv[2], "w"), indent=1)
PY
}

# 1. Every coil off at start and at exit.
start_module module.log 16
if [ -z "$port" ]; then
  fail "the module did not start: $(cat "$work/module.log")"
else
  write_profile "$port"
  "$bin" device -m "$work/router_coils.json" --tcp 127.0.0.1:0 --exit-after 300 \
    > "$work/device.log" 2>&1 &
  device_pid=$!
  target=
  for _ in $(seq 200); do
    target=$(sed -n 's/.*serving \(modbus-tcp:[^ ]*\).*/\1/p' "$work/device.log")
    [ -n "$target" ] && break
    kill -0 "$device_pid" 2>/dev/null || break
    sleep 0.05
  done
  [ -n "$target" ] && ok || fail "device did not start: $(cat "$work/device.log")"
  grep -q "output coils at modbus-tcp://127.0.0.1:$port?unit=1: spindle=0 flood=3; all off" \
    "$work/device.log" && ok || fail "no output coils line: $(cat "$work/device.log")"
  # The status of a device with output coils is an ordinary one.
  out=$("$bin" ctl "$target" status 2>&1) && ok || fail "ctl status: $out"
  kill -INT "$device_pid" 2>/dev/null; wait "$device_pid"; rc=$?
  [ $rc -eq 0 ] && grep -q "pathstream device: output coils off$" "$work/device.log" && ok ||
    fail "exit: $rc $(tail -5 "$work/device.log")"
  kill -TERM "$module_pid" 2>/dev/null; wait "$module_pid" 2>/dev/null
  # Spindle 0 and flood 3 are not consecutive: one FC5 each, at start and at exit.
  grep -q "^write requests 4$" "$work/module.log" && ! grep -q "^coil" "$work/module.log" && ok ||
    fail "the module saw: $(cat "$work/module.log")"
fi

# 2. No module at that port: exit 6 before anything is served.
"$bin" device -m "$work/router_coils.json" --tcp 127.0.0.1:0 --exit-after 5 > "$work/device2.log" 2>&1
rc=$?
[ $rc -eq 6 ] && grep -q "^pathstream: device: .*router_coils.json: output_coils: modbus-tcp://127.0.0.1:$port?unit=1: cannot connect" \
  "$work/device2.log" && ! grep -q "serving" "$work/device2.log" && ok ||
  fail "start without a module: $rc $(cat "$work/device2.log")"

# 3. A module with 2 coils: flood on coil 3 is refused (exception 2), the start with it.
start_module module3.log 2
if [ -n "$port" ]; then
  write_profile "$port"
  "$bin" device -m "$work/router_coils.json" --tcp 127.0.0.1:0 --exit-after 5 > "$work/device3.log" 2>&1
  rc=$?
  [ $rc -eq 6 ] && grep -q "cannot switch flood (coil 3) off: FC5 write coil 3 off: exception response 2 (illegal data address)" \
    "$work/device3.log" && ok || fail "start with a refused coil: $rc $(cat "$work/device3.log")"
  kill -TERM "$module_pid" 2>/dev/null; wait "$module_pid" 2>/dev/null
else
  fail "the second module did not start: $(cat "$work/module3.log")"
fi

# 4. A G-code job end to end: drill.ngc (T2 M6, S6000 M3 M8, ... M9 M5) streamed to the device
# switches the module's spindle and flood coils on after the tool change and off by its end.
start_module module4.log 16
if [ -n "$port" ]; then
  write_profile "$port"
  "$bin" device -m "$work/router_coils.json" --tcp 127.0.0.1:0 --time-scale 20 --exit-after 300 \
    > "$work/device4.log" 2>&1 &
  device_pid=$!
  target=
  for _ in $(seq 200); do
    target=$(sed -n 's/.*serving \(modbus-tcp:[^ ]*\).*/\1/p' "$work/device4.log")
    [ -n "$target" ] && break
    kill -0 "$device_pid" 2>/dev/null || break
    sleep 0.05
  done
  if [ -n "$target" ]; then
    "$bin" stream "$src/examples/cnc/drill.ngc" -m "$work/router_coils.json" \
      --tool-table "$src/examples/cnc/tools.tbl" -t "$target" --no-journal \
      < /dev/null > "$work/stream4.log" 2>&1 &
    stream_pid=$!
    for _ in $(seq 2400); do
      kill -0 "$stream_pid" 2>/dev/null || break
      if "$bin" ctl "$target" status --json 2>/dev/null | grep -q '"paused": true'; then
        # In the tool change the spindle's coil has not been switched on yet.
        grep -q "^coil 0 on" "$work/module4.log" && fail "spindle coil on before the tool change"
        "$bin" ctl "$target" resume > /dev/null 2>&1
      fi
      sleep 0.05
    done
    kill -0 "$stream_pid" 2>/dev/null && { fail "stream did not end"; kill -KILL "$stream_pid"; }
    wait "$stream_pid"; rc=$?
    [ $rc -eq 0 ] && ok || fail "stream drill: $rc $(tail -5 "$work/stream4.log")"
    kill -INT "$device_pid" 2>/dev/null; wait "$device_pid" 2>/dev/null
  else
    fail "device did not start: $(cat "$work/device4.log")"
    kill "$device_pid" 2>/dev/null; wait "$device_pid" 2>/dev/null
  fi
  kill -TERM "$module_pid" 2>/dev/null; wait "$module_pid" 2>/dev/null
  # Each coil went on once and off once, in that order.
  changes=$(grep "^coil" "$work/module4.log" | tr '\n' ';')
  [ "$(grep -c "^coil 0 on" "$work/module4.log")" -eq 1 ] &&
    [ "$(grep -c "^coil 3 on" "$work/module4.log")" -eq 1 ] &&
    [ "$(grep -c "^coil 0 off" "$work/module4.log")" -eq 1 ] &&
    [ "$(grep -c "^coil 3 off" "$work/module4.log")" -eq 1 ] &&
    [ "$(grep "^coil 0" "$work/module4.log" | head -1)" = "coil 0 on" ] && ok ||
    fail "the module's coils during drill.ngc: $changes"
else
  fail "the fourth module did not start: $(cat "$work/module4.log")"
fi

echo "output coils: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
