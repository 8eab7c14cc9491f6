#!/usr/bin/env bash
# End-to-end checks of the pathstream command as a user runs it: exit codes, messages, and
# that a failed run leaves no output file behind.
#   cli_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
failures=0 passed=0
expect() {  # expect NAME EXIT_CODE MESSAGE_SUBSTRING -- command...
  local name=$1 code=$2 needle=$3; shift 4
  local out rc
  out=$("$@" 2>&1); rc=$?
  if [ "$rc" -ne "$code" ] || [[ "$out" != *"$needle"* ]]; then
    echo "FAIL $name: exit $rc (want $code), output: $out"; failures=$((failures + 1))
  else
    passed=$((passed + 1))
  fi
}

expect example 0 "every setpoint (6722) equals" -- "$bin" setpoints "$src/examples/rose.json" --out "$work/rose.csv"
rows=$(wc -l < "$work/rose.csv")
# 105 spans x 32 ticks + the end point + the header
if [ "$rows" -ne $((105 * 32 + 2)) ]; then echo "FAIL rows: $rows"; failures=$((failures + 1)); else passed=$((passed + 1)); fi
if [ "$(head -1 "$work/rose.csv")" != "tick,span,subpath,pen,x,y" ]; then echo "FAIL header"; failures=$((failures + 1)); else passed=$((passed + 1)); fi

printf '{\n  "points": [[0, 0],\n    [1, "x"]]\n}\n' > "$work/bad.json"
expect bad-file 1 "bad.json:3:9: coordinate must be a number" -- "$bin" setpoints "$work/bad.json" --out "$work/bad.csv"
if ls "$work"/bad.csv* >/dev/null 2>&1; then echo "FAIL bad-file left output behind"; failures=$((failures + 1)); else passed=$((passed + 1)); fi
expect bad-option 2 "--ticks-per-span" -- "$bin" setpoints "$src/examples/rose.json" --ticks-per-span 70000
expect missing-file 2 "file: no such file: $work/nope.json" -- "$bin" setpoints "$work/nope.json"
expect directory-file 2 "is a directory, not a path file" -- "$bin" check "$work"
out=$("$bin" check "$work/nope.svg" 2>&1)
[[ "$out" != *" OR "* ]] && passed=$((passed + 1)) || { echo "FAIL missing-file message has CLI11's OR: $out"; failures=$((failures + 1)); }
expect no-subcommand 2 "A subcommand is required" -- "$bin"
expect unwritable 3 "cannot create output file" -- "$bin" setpoints "$src/examples/rose.json" --out "$work/no/such/dir/x.csv"
expect help 0 "--ticks-per-span" -- "$bin" setpoints --help

# eval: N samples per span plus the end point, header span,u,x,y, values exact to one LSB
expect eval 0 "25 samples of 1 subpath(s) in mm" -- "$bin" eval "$src/examples/wave.json" --samples-per-span 4 --out "$work/wave.csv"
if [ "$(head -1 "$work/wave.csv")" != "span,u,x,y" ] || [ "$(sed -n 3p "$work/wave.csv")" != "0,0.25,2.5,2.375" ] ||
   [ "$(tail -1 "$work/wave.csv")" != "5,1,60,0" ]; then
  echo "FAIL eval output: $(head -3 "$work/wave.csv" | tr '\n' ' ') ... $(tail -1 "$work/wave.csv")"; failures=$((failures + 1))
else
  passed=$((passed + 1))
fi
printf '{"units": "in", "basis": "polyline", "points": [[0, 0], [1, 0.5]]}' > "$work/inch.json"
out=$("$bin" eval "$work/inch.json" --samples-per-span 2 2>/dev/null | tail -1)
if [ "$out" != "0,1,1,0.5" ]; then echo "FAIL eval-inches: $out"; failures=$((failures + 1)); else passed=$((passed + 1)); fi
expect eval-unknown-type 1 "unknown file type" -- "$bin" eval "$src/README.md"

# check, plan and sim on the example drawing and machine
machine="$src/examples/machines/pen_plotter.json"
expect check 0 "subpaths: 2" -- "$bin" check "$src/examples/rose.json"
expect check-gcode 0 "valid" -- "$bin" check "$src/examples/leaf.ngc"
# Order defaults: G-code keeps the program's order unless --order; eval and setpoints keep the
# file's order and direction; SVG is ordered by default in check.
printf 'G21 G90\nG0 Z1\nG0 X50 Y0\nG1 Z-1 F600\nG1 X60 Y0\nG0 Z1\nG0 X0 Y0\nG1 Z-1\nG1 X10 Y0\nG0 Z1\nM2\n' > "$work/two_cuts.ngc"
expect gcode-keeps-order 0 "order: as in the file (G-code keeps the program's order; --order to reorder)" -- \
  "$bin" check "$work/two_cuts.ngc"
expect gcode-order-asked 0 "order: pen-up travel from the start" -- "$bin" check "$work/two_cuts.ngc" --order
expect order-and-keep 2 "excludes" -- "$bin" check "$work/two_cuts.ngc" --order --keep-order
# A single open B-spline whose end is nearer the origin than its start: eval keeps its direction.
printf '{"basis": "bspline", "subpaths": [{"points": [[90,90],[60,60],[30,30],[10,10],[1,1]]}]}' > "$work/toward_origin.json"
first=$("$bin" eval "$work/toward_origin.json" -n 1 -o - 2>/dev/null | sed -n 2p)
[[ "$first" == 0,0,90,90* ]] && passed=$((passed + 1)) || { echo "FAIL eval-keeps-direction: first row $first"; failures=$((failures + 1)); }
expect check-orders-json 0 "order: pen-up travel from the start" -- "$bin" check "$work/toward_origin.json"
expect check-gcode-pen 0 "G-code pen: z (auto: Z goes both above and to or below --gcode-z-down 0 mm)" -- \
  "$bin" check "$src/examples/leaf.ngc" --gcode-pen auto
printf 'M300 S440\nG0 X1\nG1 X5 Y5\n' > "$work/nopen.ngc"
expect check-gcode-motion 0 "G-code pen: motion (auto: no M3/M4 and Z never crosses --gcode-z-down 0 mm, so G1 draws and G0 travels)" -- \
  "$bin" check "$work/nopen.ngc" --gcode-pen auto
printf '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">\n<text x="1" y="2">a</text><text>b</text>\n<path d="M0 0 L 10 10" stroke="black"/></svg>\n' > "$work/text.svg"
expect check-svg-warning 0 "pathstream: warning: $work/text.svg:2:1: <text> is not drawn (convert text to paths to plot it) (2 times; the first here)" -- \
  "$bin" check "$work/text.svg"
expect check-gcode-warning 0 "pathstream: warning: $work/nopen.ngc:1:1: M300 skipped" -- \
  "$bin" check "$work/nopen.ngc" --gcode-pen motion
expect check-gcode-ignore 1 "m301.ngc:1:1: unsupported M code M301" -- \
  bash -c "sed 's/M300/M301/' '$work/nopen.ngc' > '$work/m301.ngc' && '$bin' check '$work/m301.ngc' --gcode-pen motion"
expect check-gcode-ignored 0 "M301 skipped" -- "$bin" check "$work/m301.ngc" --gcode-pen motion --ignore-code M301
expect plan 0 "within limits; no motion while the pen moves" -- "$bin" plan "$src/examples/rose.json" -m "$machine" --out "$work/plan.csv"
if [ "$(head -1 "$work/plan.csv")" != "tick,t,x,y,pen" ] || [ "$(sed -n 2p "$work/plan.csv" | cut -d, -f1-2)" != "0,0" ]; then
  echo "FAIL plan csv: $(head -2 "$work/plan.csv" | tr '\n' ' ')"; failures=$((failures + 1))
else
  passed=$((passed + 1))
fi
expect sim 0 "0 underruns" -- "$bin" sim "$src/examples/rose.json" -m "$machine" --plot "$work/plots"
for f in path.svg speed.svg acceleration.svg; do
  if [ -s "$work/plots/$f" ]; then passed=$((passed + 1)); else echo "FAIL sim did not write $f"; failures=$((failures + 1)); fi
done
# sim plans as the device runs and keeps a record of bounded size; --plan-first holds the whole
# plan and every tick. Both report the same figures (wall time aside), and a run short enough to
# keep every tick (wave.json, 1144 ticks) draws the very same plots.
same_sim() {  # same_sim NAME FILE [sim options]: the --json documents agree but for wall time
  local name=$1 file=$2; shift 2
  "$bin" sim "$file" -m "$machine" --json "$@" > "$work/$name.streamed.json" 2>/dev/null &&
    "$bin" sim "$file" -m "$machine" --json --plan-first "$@" > "$work/$name.first.json" 2>/dev/null &&
    /usr/bin/python3 - "$work/$name.streamed.json" "$work/$name.first.json" <<'PY'
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
for doc in (a, b):
    for key in ("wall_time_s", "speedup", "plots", "plot_note"):
        doc.pop(key, None)
if a != b:
    for key in sorted(set(a) | set(b)):
        if a.get(key) != b.get(key):
            print(f"{key}: streamed {a.get(key)}, --plan-first {b.get(key)}")
    sys.exit(1)
PY
}
same_sim wave "$src/examples/wave.json" --plot "$work/wave-streamed" && passed=$((passed + 1)) ||
  { echo "FAIL sim wave.json: streamed and --plan-first reports differ"; failures=$((failures + 1)); }
"$bin" sim "$src/examples/wave.json" -m "$machine" --plan-first --plot "$work/wave-first" > /dev/null 2>&1
for f in path.svg speed.svg acceleration.svg; do
  cmp -s "$work/wave-streamed/$f" "$work/wave-first/$f" && passed=$((passed + 1)) ||
    { echo "FAIL sim wave.json: $f differs from --plan-first's"; failures=$((failures + 1)); }
done
same_sim rose "$src/examples/rose.json" --plant ideal && passed=$((passed + 1)) ||
  { echo "FAIL sim rose.json: streamed and --plan-first reports differ"; failures=$((failures + 1)); }
same_sim leaf "$src/examples/leaf.ngc" && passed=$((passed + 1)) ||
  { echo "FAIL sim leaf.ngc: streamed and --plan-first reports differ"; failures=$((failures + 1)); }
# A slow job keeps sim's memory flat: 150 short G1 moves at F10 mm/min, 1.8 million ticks,
# within an address-space ceiling (RLIMIT_AS; the planning threads' stacks and malloc arenas
# count: it passes from about 120 MB, 18 MB resident). With every tick kept (--plan-first, and
# sim before it planned as it ran) it takes 256 MB resident and fails under 300 MB. The plots
# without PNG copies: rsvg-convert would run under the ceiling too. Sanitizers reserve
# terabytes of shadow address space: there it runs without the ceiling.
awk 'BEGIN { srand(7); print "G21 G90\nG0 Z3\nG0 X20 Y20\nG1 Z-0.5 F600";
  for (i = 0; i < 150; i++) printf "G1 X%.3f Y%.3f F10\n", 20 + (i % 20) * 1.0 + rand(), 20 + int(i / 20) * 1.0 + rand();
  print "G0 Z3\nM2" }' > "$work/slow.ngc"
ceiling="ulimit -v 200000 &&"
[ -n "${PATHSTREAM_SANITIZED:-}" ] && ceiling=''
expect sim-slow-flat-memory 0 "0 underruns" -- \
  bash -c "$ceiling PATH=/nonexistent exec \"$bin\" sim \"$work/slow.ngc\" -m \"$machine\" --plot \"$work/slow-plots\""
[ -s "$work/slow-plots/speed.svg" ] && passed=$((passed + 1)) || { echo "FAIL sim slow.ngc wrote no speed.svg"; failures=$((failures + 1)); }
printf '{"axes": [{"name": "x", "max_velocity": 100, "max_acceleration": 1000}]}' > "$work/one_axis.json"
expect axes-mismatch 1 "the machine has 1 axes but" -- "$bin" plan "$src/examples/rose.json" -m "$work/one_axis.json"
printf '{"axes": [{"name": "x", "max_velocity": -1, "max_acceleration": 1000}]}' > "$work/bad_machine.json"
expect bad-machine 1 "bad_machine.json:1:41: max_velocity -1 mm/s is impossible" -- "$bin" plan "$src/examples/rose.json" -m "$work/bad_machine.json"

# pathstream device --machine: configured from the profile; GPIO errors name chip and line.
gpio_machine="$src/examples/machines/pen_plotter_gpio.json"
sed 's/"gpiochip0"/"no-such-chip"/' "$gpio_machine" > "$work/gpio_nochip.json"
expect device-machine 0 "x 250000 LSB/s 3000000 LSB/s^2" -- "$bin" device -m "$gpio_machine" --no-gpio --tcp 127.0.0.1:0 --exit-after 0.05
expect device-no-chip 6 'gpio no-such-chip line "17": no GPIO chip is named or labelled "no-such-chip"' -- "$bin" device -m "$work/gpio_nochip.json" --tcp 127.0.0.1:0 --exit-after 0.05
expect device-home-no-gpio 2 'no "gpio" object: --home has no switches' -- "$bin" device -m "$machine" --home --exit-after 0.05
expect device-home-needs-machine 2 "--home: needs --machine" -- "$bin" device --home
vm_profile=$src/sim/gpio/vm/gpio_vm_profile.json
# serve on a port another serve holds: exit 3, and its temporary state directory is gone.
serve_port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
"$bin" serve -m "$machine" -t "modbus-tcp://127.0.0.1:1?unit=1" --listen "127.0.0.1:$serve_port" > "$work/serve1.log" 2>&1 &
serve_pid=$!
for _ in $(seq 200); do grep -q "pathstream serve: http" "$work/serve1.log" && break; sleep 0.05; done
tmp_before=$(ls -d "${TMPDIR:-/tmp}"/pathstream-serve-* 2>/dev/null | wc -l)
expect serve-port-in-use 3 "cannot listen on 127.0.0.1:$serve_port (Address already in use)" -- \
  "$bin" serve -m "$machine" -t "modbus-tcp://127.0.0.1:1?unit=1" --listen "127.0.0.1:$serve_port"
tmp_after=$(ls -d "${TMPDIR:-/tmp}"/pathstream-serve-* 2>/dev/null | wc -l)
[ "$tmp_after" -eq "$tmp_before" ] && passed=$((passed + 1)) || { echo "FAIL serve-port-in-use left a state directory"; failures=$((failures + 1)); }
kill -INT "$serve_pid" 2>/dev/null; wait "$serve_pid" 2>/dev/null
expect sim-switch-needs-machine 2 "--sim-switch: needs --machine" -- "$bin" device --sim-switch x-=1
expect sim-switch-bounce-alone 2 "--switch-bounce: needs --sim-switch" -- "$bin" device -m "$vm_profile" --switch-bounce 2
expect sim-switch-no-gpio 2 "not with --no-gpio" -- "$bin" device -m "$vm_profile" --no-gpio --sim-switch x-=1
expect sim-switch-unknown 2 "gpio_vm_profile.json has no limit switch z- (its switches: x-, y+)" -- "$bin" device -m "$vm_profile" --sim-switch z-=1
expect sim-switch-twice 2 "--sim-switch x-: given twice" -- "$bin" device -m "$vm_profile" --sim-switch x-=1 --sim-switch x-=2
expect sim-switch-form 2 "want NAME=POSITION" -- "$bin" device -m "$vm_profile" --sim-switch x-
expect sim-switch-position 2 "--sim-switch x-: 'abc' is not a number" -- "$bin" device -m "$vm_profile" --sim-switch x-=abc
expect stream-lead-in-can 6 "nosuchcan0: no such interface" -- "$bin" stream "$src/examples/rose.json" -m "$machine" -t "can://nosuchcan0?node=1" --lead-in
printf 'G21 G90\nG0 X10 Y10\nG1 Z-1 F1000\nG1 X50 Y10\nG1 X500 Y10\n' > "$work/wide.ngc"
expect check-machine-travel 1 "wide.ngc:5:1: subpath 1 leaves the work area: it reaches x = 500.000 mm" -- \
  "$bin" check "$work/wide.ngc" -m "$src/examples/machines/a3_plotter.json"
expect margin-without-fit 2 "--margin requires --fit" -- "$bin" check "$src/examples/landscape.svg" --margin 10
expect stream-lead-in-twice 2 "--lead-in excludes --no-lead-in" -- "$bin" stream "$src/examples/rose.json" -m "$machine" -t "modbus-tcp://127.0.0.1:1" --lead-in --no-lead-in
expect stream-lead-in-cia402 2 "--lead-in: CiA 402 drives must stand at the drawing's first point" -- "$bin" stream "$src/examples/rose.json" -m "$machine" -t "can://vcan0?node=1&protocol=cia402" --lead-in
expect stream-cia402-bad-ff 2 "ff 'fast' is not none, velocity or torque" -- "$bin" stream "$src/examples/rose.json" -m "$machine" -t "can://vcan0?node=1&protocol=cia402&ff=fast"
expect stream-cia402-torque-no-inertia 2 "ff=torque needs inertia=X" -- "$bin" stream "$src/examples/rose.json" -m "$machine" -t "can://vcan0?node=1&protocol=cia402&ff=torque"
expect drive-bad-inertia 2 "--inertia" -- "$bin" drive --can vcan0 --inertia -1
expect stream-resume-lead-in 2 "--resume: --no-lead-in does not apply" -- "$bin" stream --resume "$src/examples/rose.json" --no-lead-in
expect device-axes-and-machine 2 "the axis count comes from --machine" -- "$bin" device -m "$machine" --axes 3

# The work area: a drawing larger than the A3 plotter's travel is refused at its element with
# the offending point; --fit a4 places it; the profile's per-layer feed shows in check.
a3="$src/examples/machines/a3_plotter.json"
printf '<svg xmlns="http://www.w3.org/2000/svg" width="2000mm" height="900mm" viewBox="0 0 2000 900">\n<rect x="10" y="10" width="1980" height="880" fill="none" stroke="black"/>\n</svg>\n' > "$work/big.svg"
expect work-area 1 'big.svg:2:1: subpath 1 leaves the work area: it reaches x = 1990.000 mm at (1990.000, 10.000) mm; x travel is 0.000 .. 430.000 mm' -- "$bin" plan "$work/big.svg" -m "$a3"
expect work-area-fit 0 'every tick checked' -- "$bin" plan "$work/big.svg" -m "$a3" --fit a4
expect layer-feed 0 '"accent" 2 subpaths 88.0 mm at 40.0 mm/s' -- "$bin" check "$src/examples/two_pens.svg" -m "$a3"
# Fitted to the whole travel, or to a paper as large as it, a drawing plans: the fit keeps the
# chord tolerance and one LSB inside. A paper larger than the travel names the one that fits.
expect fit-area 0 'every tick checked' -- "$bin" plan "$src/examples/landscape.svg" -m "$a3" --fit area
expect fit-a4-full-height 0 'every tick checked' -- "$bin" plan "$src/examples/landscape.svg" -m "$a3" --fit a4
expect fit-a3-portrait 2 'the paper (297 x 420 mm) does not fit the machine'"'"'s work area (430 x 297 mm from (0, 0) mm); --fit a3-landscape does' -- \
  "$bin" plan "$src/examples/landscape.svg" -m "$a3" --fit a3

# Layers and pen changes; one CLI: standard input and -o - everywhere.
expect layers-plan 0 'layers: 2 ("outline" 2 subpaths' -- "$bin" plan "$src/examples/two_pens.svg" -m "$machine"
expect layers-pause 0 '1 pause for the operator' -- "$bin" plan "$src/examples/two_pens.svg" -m "$machine"
expect layers-one 0 'layers: 2 ("outline" 0 subpaths 0.0 mm, "accent" 2 subpaths' -- "$bin" check "$src/examples/two_pens.svg" --layer accent
expect layers-no-pause 0 '0 pauses for the operator' -- "$bin" check "$src/examples/two_pens.svg" --pause none
expect layers-same-pen 0 '0 pauses for the operator' -- "$bin" check "$src/examples/landscape.svg"
expect layers-every 0 '6 pauses for the operator' -- "$bin" check "$src/examples/landscape.svg" --pause layer
expect layers-unknown 2 '--layer 3: no such layer (the drawing has 1: "outline", 2: "accent")' -- "$bin" check "$src/examples/two_pens.svg" --layer 3
expect stdin-json 0 '<stdin>: valid, 2 axes' -- bash -c "\"$bin\" check - < \"$src/examples/rose.json\""
expect stdin-svg 0 'layers: 2' -- bash -c "cat \"$src/examples/two_pens.svg\" | \"$bin\" check -"
expect stdin-bad 1 '<stdin>:1:2: invalid JSON' -- bash -c "echo '{oops' | \"$bin\" check -"
expect stdin-empty 1 'standard input is empty' -- bash -c "\"$bin\" check - < /dev/null"
expect format-option 1 'rose.json' -- "$bin" check "$src/examples/rose.json" --format svg
expect setpoints-svg 0 'every setpoint' -- "$bin" setpoints "$src/examples/two_pens.svg" -m "$machine" -o -
expect eval-stdout 0 'span,u,x,y' -- "$bin" eval "$src/examples/rose.json" -o -
[ ! -e "$src/-" ] && [ ! -e ./- ] && passed=$((passed + 1)) || { echo "FAIL: a file named - was written"; failures=$((failures + 1)); }

# 10^6-point files are checked within an address-space limit (RLIMIT_AS, more than the resident
# memory), in file order and ordered: a CSV once needed 574 MB resident (every Bezier segment and
# several copies of the path held at once), a JSON file ~600 MB (its document tree of every
# number), SVG and G-code 380 MB ordered (every line a Bezier segment of 3 points, each point a
# vector of its own). Points are stored flat and lines stay polylines now: each of the eight runs
# passes within 85 MB of address space (docs/cli.md); the ceilings keep a margin for other
# allocators and libraries.
# 1,000 subpaths of 1,000 points but the CSV (one subpath), as docs/cli.md measures them.
# Sanitizers reserve terabytes of shadow address space, so there is no ceiling to hold them to:
# under them these runs would only repeat, at ten times the cost, what the readers' sanitized
# unit tests and fuzz targets already cover.
if [ -z "${PATHSTREAM_SANITIZED:-}" ]; then
awk 'BEGIN { for (i = 0; i < 1000000; i++) printf "%.4f,%.4f\n", 100 + 80 * cos(i * 0.001), 100 + 80 * sin(i * 0.001) }' \
  > "$work/million.csv"
awk -F, 'BEGIN { printf "{\"basis\": \"polyline\", \"subpaths\": [" }
  { printf "%s[%s, %s]", (NR % 1000 == 1 ? (NR > 1 ? "]},\n" : "") "{\"points\": [" : ", "), $1, $2 }
  END { print "]}]}" }' "$work/million.csv" > "$work/million.json"
awk -F, 'BEGIN { print "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"300mm\" height=\"300mm\" viewBox=\"0 0 300 300\">" }
  { printf "%s%s %s", (NR % 1000 == 1 ? (NR > 1 ? "\"/>\n" : "") "<path fill=\"none\" stroke=\"black\" d=\"M " : " L "), $1, $2 }
  END { print "\"/>\n</svg>" }' "$work/million.csv" > "$work/million.svg"
awk -F, '{ if (NR % 1000 == 1) printf "G0 Z1\nG0 X%s Y%s\nG1 Z0\n", $1, $2; else printf "G1 X%s Y%s\n", $1, $2 }
  END { print "G0 Z1" }' "$work/million.csv" > "$work/million.gcode"
# FORMAT:ORDER:CEILING_KB; ORDER keep: --keep-order, order: the path order (joins touching ends).
for run in csv:keep:120000 json:keep:120000 svg:keep:120000 gcode:keep:120000 \
           csv:order:120000 json:order:120000 svg:order:120000 gcode:order:120000; do
  format=${run%%:*}
  order=${run#*:}
  order=${order%%:*}
  ceiling="ulimit -v ${run##*:} &&"
  points='1000 points'  # lines stay polylines: one point a vertex
  [ "$format" = csv ] && points='1000000 points'
  flag='--keep-order'
  if [ "$order" = order ]; then
    flag=''
    [ "$format" = gcode ] && flag='--order'  # G-code keeps the program's order by default
    points='1000 subpaths -> 710 (merged 290)'
    [ "$format" = csv ] && points='1 subpaths -> 1 (merged 0)'
  fi
  expect "million-points-$format-$order" 0 "$points" -- \
    bash -c "$ceiling \"$bin\" check \"$work/million.$format\" $flag"
done
rm -f "$work"/million.*
fi

echo "cli: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
