#!/usr/bin/env bash
# `check`, `plan` and `sim` with --json: standard output is exactly one JSON document whose
# figures are the text report's (compared at the text's precision), and an error prints
# nothing on standard output and keeps its exit code.
#   json_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
py=/usr/bin/python3
rm -rf "$work" && mkdir -p "$work"
machine="$src/examples/machines/pen_plotter.json"
failures=0 passed=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }

# run NAME ARGS...: the text run to NAME.txt, the --json run to NAME.json; both must exit 0.
run() {
  local name=$1 rc
  shift
  "$bin" "$@" > "$work/$name.txt" 2> "$work/$name.txt.err"; rc=$?
  [ "$rc" -eq 0 ] || fail "$name text: exit $rc: $(cat "$work/$name.txt.err")"
  "$bin" "$@" --json > "$work/$name.json" 2> "$work/$name.json.err"; rc=$?
  [ "$rc" -eq 0 ] || fail "$name --json: exit $rc: $(cat "$work/$name.json.err")"
}

# compare NAME PYTHON: PYTHON sees `text` (the text output), `doc` (the parsed JSON, which must
# be the whole of standard output) and `same(label, text_value, json_text)`; it exits non-zero
# (printing why) when a figure differs.
compare() {
  local name=$1 out
  if out=$("$py" - "$work/$name.txt" "$work/$name.json" 2>&1 <<EOF
import json, re, sys
text = open(sys.argv[1]).read()
doc = json.loads(open(sys.argv[2]).read())  # raises unless the whole output is one document
bad = []
def same(label, want, got):
    if str(want) != str(got):
        bad.append("%s: text %s, json %s" % (label, want, got))
def find(pattern):
    m = re.search(pattern, text, re.M)
    if not m:
        bad.append("text has no match for %r" % pattern)
        return ("?",) * 20
    return m.groups()
$2
if bad:
    print("; ".join(bad))
    sys.exit(1)
EOF
  ); then
    passed=$((passed + 1))
  else
    fail "$name: $out"
  fi
}

run check check "$src/examples/rose.json"
compare check '
axes, units = find(r"valid, (\d+) axes, units (\S+)")
same("axes", axes, doc["axes"]); same("units", units, doc["units"])
same("subpaths", find(r"subpaths: (\d+)")[0], doc["subpath_count"])
same("subpath list", doc["subpath_count"], len(doc["subpaths"]))
draw, travel = find(r"spans: (\d+) drawing, (\d+) travel")
same("drawing spans", draw, doc["drawing_spans"]); same("travel spans", travel, doc["travel_spans"])
drawn, up = find(r"length: (\S+) mm drawn, (\S+) mm pen-up")
same("drawn", drawn, "%.3f" % doc["drawn_length_mm"]); same("travel", up, "%.3f" % doc["travel_length_mm"])
for axis, lo, hi in re.findall(r" (\w) (-?[\d.]+) \.\. (-?[\d.]+) mm", text):
    box = doc["bounding_box_mm"][axis]
    same("box " + axis, lo + " " + hi, "%.3f %.3f" % (box["min"], box["max"]))
same("box axes", len(re.findall(r" \.\. ", text)), len(doc["bounding_box_mm"]))
'

run check-gcode check "$src/examples/leaf.ngc"
compare check-gcode '
same("drawn", find(r"length: (\S+) mm drawn")[0], "%.3f" % doc["drawn_length_mm"])
same("basis", find(r"0: (\w+),")[0], doc["subpaths"][0]["basis"])
'

run plan plan "$src/examples/rose.json" -m "$machine"
compare plan '
dur, ticks, hz, spans, pens = find(r"motion: (\S+) s \((\d+) ticks at (\S+) Hz\), (\d+) spans, (\d+) pen lifts and lowers")
same("duration", dur, "%.3f" % doc["duration_s"]); same("ticks", ticks, doc["ticks"])
same("tick rate", hz, "%g" % doc["tick_hz"]); same("spans", spans, doc["spans"])
same("pen changes", pens, doc["pen_changes"])
drawn, travel = find(r"path: (\S+) mm drawn, (\S+) mm travel")
same("drawn", drawn, "%.3f" % doc["drawn_length_mm"]); same("travel", travel, "%.3f" % doc["travel_length_mm"])
dev, tol, tick = find(r"max deviation from the path: (\S+) um \(tolerance (\S+) um\) at tick (\d+)")
same("deviation", dev, "%.2f" % (doc["max_deviation_mm"] * 1000))
same("tolerance", tol, "%.2f" % (doc["chord_tolerance_mm"] * 1000)); same("deviation tick", tick, doc["max_deviation_tick"])
rows = re.findall(r"axis (\w+): exact cubic peak (\S+) % of max velocity, (\S+) % of max acceleration; "
                  r"setpoints (\d+) of (\S+) LSB/tick, (\d+) of (\S+) LSB/tick\^2", text)
same("axis count", len(rows), len(doc["axes"]))
for name, v, a, step, vlim, diff2, alim in rows:
    x = doc["axes"][name]
    same(name + " v cubic", v, "%.2f" % (100 * x["velocity_fraction_cubic"]))
    same(name + " a cubic", a, "%.2f" % (100 * x["acceleration_fraction_cubic"]))
    same(name + " step", step, x["max_step_lsb_per_tick"]); same(name + " v lim", vlim, "%.4g" % x["velocity_limit_lsb_per_tick"])
    same(name + " 2nd diff", diff2, x["max_second_difference_lsb_per_tick2"])
    same(name + " a lim", alim, "%.4g" % x["acceleration_limit_lsb_per_tick2"])
same("ticks checked", find(r"every tick checked \((\d+)\)")[0], doc["ticks_checked"])
same("within limits", "within limits;" in text, doc["within_limits"])
same("pen motion", "MOTION WHILE" in text, doc["motion_while_pen_moves"])
'

# The sim report of both plants: the servo one has following errors.
sim_figures='
axes, hz, lsb = find(r"machine +(\d+) axes \(.*\), (\S+) Hz tick, (\S+) mm/LSB")
same("axes", axes, doc["machine"]["axes"]); same("tick rate", hz, "%.6g" % doc["machine"]["tick_hz"])
same("lsb", lsb, "%.6g" % doc["machine"]["mm_per_lsb"])
same("plant", find(r"plant +(.*)$")[0], doc["plant"]["description"])
planned, simulated = find(r"duration +(\S+) s planned; (\S+) s simulated")
same("planned", planned, "%.3f" % doc["planned_duration_s"]); same("simulated", simulated, "%.3f" % doc["simulated_duration_s"])
drawn, travel, switches = find(r"path +(\S+) mm pen-down, (\S+) mm travel, (\d+) pen lifts and lowers")
same("drawn", drawn, "%.2f" % doc["drawn_length_mm"]); same("travel", travel, "%.2f" % doc["travel_length_mm"])
same("switches", switches, doc["pen_switches"])
downs, ups, down_s, pct, dwell = find(r"pen +(\d+) down, (\d+) up; down (\S+) s \((\d+) %\), dwells (\S+) s")
pen = doc["pen"]
same("pen", " ".join([downs, ups, down_s, pct, dwell]), "%d %d %.3f %.0f %.3f" % (
     pen["downs"], pen["ups"], pen["down_time_s"], 100 * pen["down_fraction"], pen["dwell_time_s"]))
ticks, spans, under = find(r"device +(\d+) ticks, (\d+) spans, (\d+) underruns")
dev = doc["device"]
same("device", " ".join([ticks, spans, under]), "%d %d %d" % (dev["ticks"], dev["spans"], dev["underruns"]))
dev_um, tick, tol = find(r"deviation +(\S+) um max \(tick (\d+)\), tolerance (\S+) um")
same("deviation", dev_um, "%.2f" % (1000 * doc["max_deviation_mm"])); same("deviation tick", tick, doc["max_deviation_tick"])
same("tolerance", tol, "%.2f" % (1000 * doc["chord_tolerance_mm"]))
v, a = find(r"limits +within the axis limits \(exact cubic peak: v (\S+) %, a (\S+) %\)")
same("v cubic peak", v, "%.2f" % (100 * doc["velocity_fraction_cubic"]))
same("a cubic peak", a, "%.2f" % (100 * doc["acceleration_fraction_cubic"]))
rows = re.findall(r"^  (\w+) +(\S+) +(\d+) of (\S+) +(\S+) +(\S+) +(\d+) of (\S+) +(\S+)$", text, re.M)
same("axis rows", len(rows), len(doc["axes"]))
for name, vc, step, vlim, ve, ac, diff2, alim, ae in rows:
    x = doc["axes"][name]
    same(name + " row", " ".join([vc, step, vlim, ve, ac, diff2, alim, ae]), "%.2f %d %.4g %.1f %.2f %d %.4g %.1f" % (
         100 * x["velocity_fraction_cubic"], x["max_step_lsb_per_tick"], x["velocity_limit_lsb_per_tick"],
         100 * x["velocity_fraction_executed"], 100 * x["acceleration_fraction_cubic"],
         x["max_second_difference_lsb_per_tick2"], x["acceleration_limit_lsb_per_tick2"],
         100 * x["acceleration_fraction_executed"]))
h, noise = find(r"executed +setpoint differences over \+/-(\d+) ticks \(a noise <= (\d+) mm/s\^2\)")
same("window", h, doc["executed_window_ticks"]); same("noise", noise, "%.0f" % doc["executed_acceleration_noise_mm_per_s2"])
for name, mx, rms in re.findall(r"^  (\w+) +(\d+\.\d) +(\d+\.\d)$", text, re.M):
    x = doc["axes"][name]
    same(name + " following", mx + " " + rms, "%.1f %.1f" % (1000 * x["max_following_error_mm"], 1000 * x["rms_following_error_mm"]))
'
run sim-ideal sim "$src/examples/rose.json" -m "$machine" --plant ideal
compare sim-ideal "$sim_figures"'
same("ideal following", "following error: 0 (ideal plant" in text, doc["axes"]["x"]["max_following_error_mm"] == 0)
'
run sim-servo sim "$src/examples/wave.json" -m "$machine" --plot "$work/plots"
compare sim-servo "$sim_figures"'
same("following rows", len(re.findall(r"^  (\w+) +(\d+\.\d) +(\d+\.\d)$", text, re.M)), len(doc["axes"]))
same("plots", find(r"^plots: (.*)$")[0], " ".join(doc["plots"]))
'

# Errors: the same exit code with and without --json, and nothing on standard output.
# error NAME ARGS...
error() {
  local name=$1 rc_text rc_json
  shift
  "$bin" "$@" > /dev/null 2>&1; rc_text=$?
  "$bin" "$@" --json > "$work/$name.out" 2> "$work/$name.err"; rc_json=$?
  if [ "$rc_json" -eq 0 ] || [ "$rc_json" -ne "$rc_text" ]; then
    fail "$name: exit $rc_json with --json, $rc_text without"
  elif [ -s "$work/$name.out" ] || [ ! -s "$work/$name.err" ]; then
    fail "$name: stdout '$(cat "$work/$name.out")', stderr '$(cat "$work/$name.err")'"
  else
    passed=$((passed + 1))
  fi
}
printf '{"points": [[0, 0], [1, "x"]]}' > "$work/bad.json"
error check-missing check "$work/nope.json"
error check-bad-file check "$work/bad.json"
for cmd in plan sim; do
  error "$cmd-missing" "$cmd" "$work/nope.json" -m "$machine"
  error "$cmd-bad-file" "$cmd" "$work/bad.json" -m "$machine"
done
error sim-unwritable-plot sim "$src/examples/wave.json" -m "$machine" --plot "$work/bad.json/plots"

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
