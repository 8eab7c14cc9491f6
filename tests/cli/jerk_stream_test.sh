#!/usr/bin/env bash
# A jerk-limited machine end to end: the pen plotter's profile with max_jerk on both axes,
# `pathstream plan` within it (the check's jerk lines), then `pathstream stream` of the same
# drawing to `pathstream device` serving that profile over Modbus TCP: the device checks every
# span's jerk and every join's acceleration step exactly and must refuse none.
#   jerk_stream_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
ok() { passed=$((passed + 1)); }
machine=$work/jerk_plotter.json
/usr/bin/python3 - "$src/examples/machines/pen_plotter.json" "$machine" <<'PY'
import json, sys
profile = json.load(open(sys.argv[1]))
for axis in profile["axes"]:
    axis["max_jerk"] = 1e6
json.dump(profile, open(sys.argv[2], "w"))
PY

out=$("$bin" plan "$src/examples/rose.json" -m "$machine" 2>&1); rc=$?
[ $rc -eq 0 ] && [[ "$out" == *"within limits"* && "$out" == *"of max jerk"* ]] && ok || fail "plan: $rc $out"

"$bin" device -m "$machine" --no-gpio --tcp 127.0.0.1:0 --position 139.322,100 --time-scale 10 \
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
else
  out=$("$bin" stream "$src/examples/rose.json" --keep-order -m "$machine" -t "$target" --no-journal 2>&1); rc=$?
  [ $rc -eq 0 ] && [[ "$out" == *"finished: the device is idle at the drawing's end point"* ]] && ok ||
    fail "stream: $rc $out"
fi
kill -INT "$device_pid" 2>/dev/null; wait "$device_pid" 2>/dev/null
grep -q "(0 refused)" "$work/device.log" && ok || fail "the device refused requests: $(tail -5 "$work/device.log")"

echo "jerk stream: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
