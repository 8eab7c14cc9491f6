#!/usr/bin/env bash
# Parametric curves from a JSON path: examples/curves.json (circle, ellipse, Lissajous,
# hypotrochoid, involute flank, clothoid) checked and planned on the pen plotter within the
# tolerance; expression errors at their column; the helix of examples/helix.json streamed to
# the simulated 3-axis router over Modbus TCP, the device's record of every tick equal to the
# plan's.
#   curves_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
failures=0 passed=0
ok() { passed=$((passed + 1)); }
fail() { echo "FAIL $*"; failures=$((failures + 1)); }

out=$("$bin" check "$src/examples/curves.json" 2>&1) && ok || fail "check curves.json: $out"
[[ "$out" == *"subpaths: 6"* || "$out" == *"6 subpaths"* ]] && ok || fail "check curves.json lists 6 subpaths: $out"
out=$("$bin" plan "$src/examples/curves.json" -m "$src/examples/machines/pen_plotter.json" 2>&1) &&
  ok || fail "plan curves.json: $out"
[[ "$out" == *"within limits"* ]] && ok || fail "plan curves.json: not every tick within limits: $out"
dev=$(sed -n 's/.*max deviation from the path: \([0-9.]*\) um (tolerance \([0-9.]*\) um).*/\1 \2/p' <<<"$out")
awk -v d="$dev" 'BEGIN { split(d, a, " "); exit !(a[1] != "" && a[1] + 0 <= a[2] + 0) }' && ok ||
  fail "plan curves.json: deviation above the tolerance: $dev"

# Errors: the expression's column, a curve without a tangent, a t range that does not increase.
printf '{"subpaths": [{"basis": "function", "x": "t", "y": "2*sine(t)", "t": [0, 1]}]}\n' > "$work/bad1.json"
out=$("$bin" check "$work/bad1.json" 2>&1); rc=$?
[ $rc -eq 1 ] && [ "$out" = "$work/bad1.json:1:55: y: unknown function \"sine\" (sin cos tan asin acos atan atan2 sqrt exp ln log10 abs sinh cosh tanh min max pow hypot fresnel_c fresnel_s)" ] &&
  ok || fail "bad1: $rc $out"
printf '{"subpaths": [{"basis": "function", "x": "sqrt(t)", "y": "t", "t": [0, 1]}]}\n' > "$work/bad2.json"
out=$("$bin" check "$work/bad2.json" 2>&1); rc=$?
[ $rc -eq 1 ] && [[ "$out" == "$work/bad2.json:1:15: function: the derivative of x is not finite at t=0"* ]] &&
  ok || fail "bad2: $rc $out"
printf '{"subpaths": [{"basis": "function", "x": "t", "y": "t", "t": [1, 1]}]}\n' > "$work/bad3.json"
out=$("$bin" check "$work/bad3.json" 2>&1); rc=$?
[ $rc -eq 1 ] && [ "$out" = "$work/bad3.json:1:62: t must be two finite numbers, the second larger" ] &&
  ok || fail "bad3: $rc $out"

# The helix on the router: plan, then stream to the device starting at the helix's start.
router="$src/examples/machines/router.json" helix="$src/examples/helix.json"
"$bin" plan "$helix" --keep-order -m "$router" --out "$work/plan.csv" > "$work/plan.log" 2>&1 &&
  grep -q "within limits" "$work/plan.log" && ok || fail "plan helix: $(cat "$work/plan.log")"
: > "$work/device.log"
"$bin" device -m "$router" --no-gpio --tcp 127.0.0.1:0 --position 190,150,0 --time-scale 10 \
  --record "$work/record.csv" --exit-after 300 > "$work/device.log" 2>&1 &
device_pid=$!
target=""
for _ in $(seq 200); do
  target=$(sed -n 's/.*serving \(modbus-tcp:[^ ]*\).*/\1/p' "$work/device.log")
  [ -n "$target" ] && break
  sleep 0.05
done
if [ -z "$target" ]; then
  fail "device did not start: $(cat "$work/device.log")"
else
  "$bin" stream "$helix" --keep-order -m "$router" -t "$target" --no-journal < /dev/null \
    > "$work/stream.log" 2>&1 && grep -q "finished: the device is idle at the drawing's end point" "$work/stream.log" &&
    ok || fail "stream helix: $(tail -n 8 "$work/stream.log")"
fi
kill -INT "$device_pid" 2>/dev/null; wait "$device_pid" 2>/dev/null
grep -q "(0 refused)" "$work/device.log" && ok || fail "the device refused requests: $(tail -5 "$work/device.log")"
# Every tick the device ran equals the plan's (mm with 3 decimals there, LSB of 1 um here).
/usr/bin/python3 - "$work/plan.csv" "$work/record.csv" <<'PY' && ok || fail "the device's record differs from the plan (above)"
import csv, sys
plan = list(csv.DictReader(open(sys.argv[1])))
rec = list(csv.DictReader(open(sys.argv[2])))
if len(rec) < 30000 or len(plan) != len(rec) + 1:
    print(f"record has {len(rec)} ticks, plan {len(plan)} rows")
    sys.exit(1)
bad = [i for i, (p, r) in enumerate(zip(plan, rec))
       if any(round(float(p[k]) * 1000) != int(r[k]) for k in "xyz") or p["pen"] != r["pen"]]
if bad:
    print(f"{len(bad)} ticks differ, first {bad[0]}: plan {plan[bad[0]]}, device {rec[bad[0]]}")
z = min(int(r["z"]) for r in rec)
if z != -6000:
    print(f"the helix goes down to z = {z} LSB, not -6000")
sys.exit(1 if bad or z != -6000 else 0)
PY

echo "curves_test: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
