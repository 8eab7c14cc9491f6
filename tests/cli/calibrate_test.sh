#!/usr/bin/env bash
# calibrate: the simulated machine's mode comes back from its ring-down with a proposed shaper;
# a recorded CSV gives the same; sim --shaper with that proposal cuts the residual vibration;
# missing modes, a CSV without its axis and a bad --shaper are refused with the reason.
#   calibrate_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
failures=0 passed=0
ok() { passed=$((passed + 1)); }
fail() { echo "FAIL $*"; failures=$((failures + 1)); }

machine="$src/examples/machines/pen_plotter.json"

out=$("$bin" calibrate -m "$machine" --mode x:40:0.05 --json 2>&1) && ok || fail "calibrate exits $?: $out"
echo "$out" > "$work/calibrate.json"
/usr/bin/python3 - "$work/calibrate.json" <<'PY' && ok || fail "calibrate JSON (above)"
import json, sys
d = json.load(open(sys.argv[1]))
x = d["axes"]["x"]
bad = []
if abs(x["frequency_hz"] - 40) > 0.8: bad.append(f"frequency {x['frequency_hz']}")
if abs(x["damping"] - 0.05) > 0.01: bad.append(f"damping {x['damping']}")
if x["recommended"] not in [s["type"] for s in x["shapers"]]: bad.append("recommended")
if set(d["input_shaper"]) != {"x"}: bad.append(f"snippet {d['input_shaper']}")
if bad: print(bad); sys.exit(1)
PY

out=$("$bin" calibrate -m "$machine" --mode y:33:0.08 2>&1) && ok || fail "calibrate text exits $?: $out"
[[ "$out" == *"y: simulated ring-down: 3"*" Hz, damping ratio 0.0"* ]] && ok || fail "text line: $out"
[[ "$out" == *"<- proposed"* ]] && ok || fail "a proposal: $out"
[[ "$out" == *'"input_shaper": {"y":{"type":'* ]] && ok || fail "profile snippet: $out"

# A recorded ring-down: 25 Hz, zeta 0.03, acceleration samples at 2 kHz.
/usr/bin/python3 - "$work/ring.csv" <<'PY'
import math, sys
with open(sys.argv[1], "w") as f:
    f.write("# accelerometer on the carriage\ntime,acceleration\n")
    w = 2 * math.pi * 25; z = 0.03; wd = w * math.sqrt(1 - z * z)
    for k in range(2000):
        t = k / 2000
        f.write(f"{t:.6f},{800 * math.exp(-z * w * t) * math.cos(wd * t):.6f}\n")
PY
out=$("$bin" calibrate -m "$machine" --csv "$work/ring.csv" --axis x 2>&1) && ok || fail "calibrate --csv exits $?: $out"
[[ "$out" == *"x: $work/ring.csv: 25.0"*" Hz, damping ratio 0.03"* ]] && ok || fail "csv line: $out"

# The proposal in use: sim with it cuts the ringing of the mode it was measured on.
shaper=$(/usr/bin/python3 -c "import json; d = json.load(open('$work/calibrate.json')); s = d['input_shaper']['x']; print(f\"x:{s['type']}:{s['frequency']}:{s['damping']}\")")
plain=$("$bin" sim "$src/examples/wave.json" -m "$machine" --mode x:40:0.05 --json 2>/dev/null) && ok || fail "sim without shaper"
shaped=$("$bin" sim "$src/examples/wave.json" -m "$machine" --mode x:40:0.05 --shaper "$shaper" --json 2>/dev/null) && ok || fail "sim --shaper $shaper"
/usr/bin/python3 - "$plain" "$shaped" <<'PY' && ok || fail "shaped residual (above)"
import json, sys
a, b = json.loads(sys.argv[1]), json.loads(sys.argv[2])
ra, rb = a["residual_vibration_mm"]["max"], b["residual_vibration_mm"]["max"]
if not (rb * 10 < ra): print("residual", ra, rb); sys.exit(1)
if set(b["input_shaper"]) != {"x"} or b["shaped_command_deviation_mm"] <= 0: print(b["input_shaper"]); sys.exit(1)
PY

# The device shapes with the profile's shapers and logs each one (docs/events.schema.json).
"$bin" device -m "$src/examples/machines/shaped_plotter.json" --no-gpio --tcp 127.0.0.1:0 \
    --exit-after 0.1 --log-json > "$work/device.ndjson" 2>&1 && ok || fail "shaped device exits $?"
/usr/bin/python3 - "$src/docs/events.schema.json" "$work/device.ndjson" <<'PY' && ok || fail "shaped device log (above)"
import json, sys
import jsonschema
schema = json.load(open(sys.argv[1]))
v = jsonschema.Draft202012Validator({"$defs": schema["$defs"], "$ref": "#/$defs/device_log_line"})
lines = [json.loads(l) for l in open(sys.argv[2])]
for e in lines: v.validate(e)
shapers = [e for e in lines if e["event"] == "shaper"]
if [e["axis"] for e in shapers] != ["x", "y"] or any(e["taps"] != 5 for e in shapers):
    print(shapers); sys.exit(1)
PY

out=$("$bin" calibrate -m "$machine" 2>&1); rc=$?
[[ $rc == 2 && "$out" == *"no resonant modes to measure"* ]] && ok || fail "no modes: rc $rc: $out"
out=$("$bin" calibrate -m "$machine" --csv "$work/ring.csv" 2>&1); rc=$?
[[ $rc == 2 && "$out" == *"--csv: name the axis"* ]] && ok || fail "csv without axis: rc $rc: $out"
out=$("$bin" sim "$src/examples/wave.json" -m "$machine" --shaper x:fir:40 2>&1); rc=$?
[[ $rc == 2 && "$out" == *'unknown shaper type "fir"'* ]] && ok || fail "bad --shaper: rc $rc: $out"
out=$("$bin" sim "$src/examples/wave.json" -m "$machine" --shaper x:zv:450 2>&1); rc=$?
[[ $rc == 2 && "$out" == *"at least 2 are needed"* ]] && ok || fail "unshapeable --shaper: rc $rc: $out"

echo "calibrate_test: $passed passed, $failures failed"
[[ $failures == 0 ]]
