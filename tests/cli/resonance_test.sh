#!/usr/bin/env bash
# sim with resonant modes: --mode and the profile's "resonance" give the report's modes,
# vibration and contour lines and the JSON keys; corner.svg with --plot; a bad --mode or
# profile key is refused with the bad part named.
#   resonance_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
failures=0 passed=0
ok() { passed=$((passed + 1)); }
fail() { echo "FAIL $*"; failures=$((failures + 1)); }

machine="$src/examples/machines/pen_plotter.json"
job="$src/examples/star.csv"
modes=(--mode x:40:0.05 --mode y:40:0.05)

out=$("$bin" sim "$job" -m "$machine" "${modes[@]}" --plot "$work/plots" 2>&1) && ok || fail "sim with modes exits $?: $out"
[[ "$out" == *"  modes      x: 40 Hz zeta 0.05; y: 40 Hz zeta 0.05 (position = the tool's)"* ]] && ok || fail "modes line: $out"
[[ "$out" == *"  vibration  residual after "*" stop"*": max "*" um, rms "*" um"* ]] && ok || fail "vibration line: $out"
[[ "$out" == *"  contour    error max "*" um, rms "*" um"* ]] && ok || fail "contour line: $out"
[[ "$out" == *"window 125 ticks"* ]] && ok || fail "a 40 Hz mode's window is 125 ticks: $out"
[[ "$out" == *"$work/plots/corner.svg"* ]] && ok || fail "corner.svg is listed: $out"
/usr/bin/python3 - "$work/plots/corner.svg" <<'PY' && ok || fail "corner.svg (above)"
import sys
import xml.etree.ElementTree as ET
ns = {"s": "http://www.w3.org/2000/svg"}
root = ET.parse(sys.argv[1]).getroot()
bad = []
for gid in ("path", "tool", "worst", "scale"):
    g = root.find(f".//s:g[@id='{gid}']", ns)
    if g is None:
        bad.append(f"no group {gid}")
scale = root.find(".//s:g[@id='scale']/s:text", ns)
if scale is None or not (scale.text.endswith(" um") or scale.text.endswith(" mm")):
    bad.append("no scale label")
if not root.find("s:text", ns).text.startswith("Worst contour error, "):
    bad.append("title")
if bad:
    print(bad)
    sys.exit(1)
PY

# The JSON: the figures, positive with the modes, and where they were.
"$bin" sim "$job" -m "$machine" "${modes[@]}" --json > "$work/modes.json" 2> "$work/modes.err" && ok || fail "sim --json with modes: $(cat "$work/modes.err")"
/usr/bin/python3 - "$work/modes.json" <<'PY' && ok || fail "the JSON's resonance keys (above)"
import json, sys
d = json.load(open(sys.argv[1]))
bad = []
if d["plant"]["modes"] != {"x": [{"frequency_hz": 40.0, "damping": 0.05}], "y": [{"frequency_hz": 40.0, "damping": 0.05}]}:
    bad.append(f"plant.modes {d['plant']['modes']}")
r, c = d["residual_vibration_mm"], d["contour_error_mm"]
if not (r["max"] > 0 and 0 < r["rms"] <= r["max"] and r["stops"] >= 1 and r["window_ticks"] == 125):
    bad.append(f"residual {r}")
if set(r["where"]) != {"tick", "time_s", "tool_mm", "rest_mm"} or set(r["where"]["tool_mm"]) != {"x", "y"}:
    bad.append(f"residual where {r['where']}")
if not (c["max"] > 0 and 0 < c["rms"] <= c["max"] and c["ahead_ticks"] == 64):
    bad.append(f"contour {c}")
if set(c["where"]) != {"tick", "time_s", "tool_mm", "path_mm"}:
    bad.append(f"contour where {c['where']}")
if bad:
    print(bad)
    sys.exit(1)
PY

# The ideal plant: no contour error, no residual vibration, no corner.svg.
"$bin" sim "$job" -m "$machine" --plant ideal --json --plot "$work/ideal" > "$work/ideal.json" 2>&1 && ok || fail "ideal sim: $(cat "$work/ideal.json")"
/usr/bin/python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
assert d["residual_vibration_mm"]["max"] == 0 and d["contour_error_mm"]["max"] == 0, d
' "$work/ideal.json" && ok || fail "the ideal plant measures 0"
[ ! -e "$work/ideal/corner.svg" ] && ok || fail "the ideal plant got a corner.svg"

# The profile's resonance, then --mode replacing it on x.
/usr/bin/python3 - "$machine" "$work/ringing.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["resonance"] = {"x": [{"frequency": 30, "damping": 0.02}], "y": [{"frequency": 45, "damping": 0.1}]}
json.dump(m, open(sys.argv[2], "w"), indent=2)
PY
out=$("$bin" sim "$job" -m "$work/ringing.json" --mode x:60:0.2 2>&1) && ok || fail "sim with the profile's modes: $out"
[[ "$out" == *"  modes      x: 60 Hz zeta 0.2; y: 45 Hz zeta 0.1 (position = the tool's)"* ]] && ok || fail "--mode replaces x's modes: $out"
out=$("$bin" sim "$job" -m "$work/ringing.json" --plant ideal 2>&1) && ok || fail "ideal with the profile's modes: $out"
[[ "$out" == *"  modes      none: the ideal plant ignores the profile's resonance"* ]] && ok || fail "ideal ignores the modes: $out"

# Errors name the bad part.
expect_error() {
  local want=$1 code=$2 out rc
  shift 2
  out=$("$bin" "$@" 2>&1); rc=$?
  [ "$rc" -eq "$code" ] && ok || fail "$* exits $rc, not $code: $out"
  [[ "$out" == *"$want"* ]] && ok || fail "$* says: $out (expected: $want)"
}
expect_error 'x:40:abc: damping "abc" is not a number' 2 sim "$job" -m "$machine" --mode x:40:abc
expect_error 'axis "q" is not in the machine profile (axes: x, y)' 2 sim "$job" -m "$machine" --mode q:40:0.1
expect_error 'resonant modes need the servo plant' 2 sim "$job" -m "$machine" --plant ideal --mode x:40:0.05
/usr/bin/python3 - "$machine" "$work/bad.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
text = json.dumps(m, indent=2)[:-2] + ',\n  "resonance": {"x": [{"frequency": 40, "damping": 2}]}\n}\n'
open(sys.argv[2], "w").write(text)
PY
expect_error 'bad.json:' 1 sim "$job" -m "$work/bad.json"
expect_error 'damping 2 (ratio) is impossible' 1 sim "$job" -m "$work/bad.json"

echo "resonance_test: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
