#!/usr/bin/env bash
# sim --plot on a 3-axis router (tests/data/machines/router_3axis.json: axes x, y, z; a JSON path with
# three coordinates a point, tests/data/router_pocket.json): path.svg is the isometric view
# with its rapids dashed, z.svg plots z against time, PNGs of both with rsvg-convert; a pen
# plotter's plots stay 2-D, with no z.svg.
#   plot3d_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
failures=0 passed=0
ok() { passed=$((passed + 1)); }
fail() { echo "FAIL $*"; failures=$((failures + 1)); }

router="$src/tests/data/machines/router_3axis.json"
job="$src/tests/data/router_pocket.json"
out=$("$bin" sim "$job" -m "$router" --keep-order --plot "$work/router" 2>&1) && ok || fail "sim on the router exits $?: $out"
[[ "$out" == *"3 axes (x, y, z)"* ]] && ok || fail "the report names the router's axes: $out"
[[ "$out" == *"plots: $work/router/path.svg $work/router/speed.svg $work/router/acceleration.svg $work/router/z.svg"* ]] &&
  ok || fail "the report lists the four SVGs: $out"
for f in path.svg speed.svg acceleration.svg z.svg; do
  [ -s "$work/router/$f" ] && ok || fail "sim on the router did not write $f"
done
# The SVGs' content: the isometric view with dashed rapids (ideal and executed), the axes'
# arrows and the scale; z against time with the setpoints and the servo plant.
/usr/bin/python3 - "$work/router" <<'PY' && ok || fail "the router's path.svg and z.svg (above)"
import sys
import xml.etree.ElementTree as ET
ns = {"s": "http://www.w3.org/2000/svg"}
d = sys.argv[1]
bad = []
def group(root, gid):
    return root.find(f".//s:g[@id='{gid}']", ns)
path = ET.parse(f"{d}/path.svg").getroot()
title = path.find("s:text", ns).text
if not (title.startswith("Path (isometric) \u2014 ") and title.endswith("router_pocket.json")):
    bad.append(f"path.svg title {title!r}")
for gid in ("ideal-path", "setpoints", "plant"):
    g = group(path, gid)
    if g is None:
        bad.append(f"path.svg has no group {gid}")
        continue
    up = [p for p in g.findall("s:polyline", ns) if p.get("class") == "pen-up"]
    down = [p for p in g.findall("s:polyline", ns) if (p.get("class") or "").startswith("pen-down")]
    if not up or not all(p.get("stroke-dasharray") for p in up):
        bad.append(f"path.svg {gid}: rapids (pen-up) not dashed: {len(up)} polylines")
    if not down or any(p.get("stroke-dasharray") for p in down):
        bad.append(f"path.svg {gid}: feed moves (pen-down) not solid: {len(down)} polylines")
arrows = group(path, "axis-arrows")
labels = [t.text for t in arrows.findall("s:text", ns)] if arrows is not None else []
if labels != ["x", "y", "z"]:
    bad.append(f"path.svg axis arrows {labels}")
scale = group(path, "scale")
if scale is None or not scale.find("s:text", ns).text.endswith(" mm"):
    bad.append("path.svg has no scale bar in mm")
z = ET.parse(f"{d}/z.svg").getroot()
if not z.find("s:text", ns).text.startswith("z against time"):
    bad.append("z.svg title")
for gid in ("setpoints", "plant"):
    g = group(z, gid)
    if g is None or g.find("s:polyline", ns) is None:
        bad.append(f"z.svg has no {gid} line")
ticks = [t.text for t in z.findall(".//s:text[@class='tick-label']", ns)]
if "-10" not in ticks:
    bad.append(f"z.svg's z axis does not reach the cut at -12 mm: {ticks}")
for b in bad:
    print(b)
sys.exit(1 if bad else 0)
PY
if command -v rsvg-convert > /dev/null; then
  for f in path.png speed.png acceleration.png z.png; do
    [ "$(head -c 4 "$work/router/$f" 2>/dev/null | tail -c 3)" = "PNG" ] && ok || fail "no PNG $f"
  done
else
  echo "note: rsvg-convert not on PATH: the PNGs are not checked"
fi
# --json lists z.svg among the plots.
"$bin" sim "$job" -m "$router" --keep-order --plant ideal --json --plot "$work/router-json" > "$work/router.json" 2>/dev/null &&
  /usr/bin/python3 -c 'import json, sys; sys.exit(0 if any(p.endswith("/z.svg") for p in json.load(open(sys.argv[1]))["plots"]) else 1)' \
    "$work/router.json" && ok || fail "sim --json does not list z.svg"

# A pen plotter: the 2-D path.svg, no z.svg.
"$bin" sim "$src/examples/wave.json" -m "$src/examples/machines/pen_plotter.json" --plot "$work/plotter" > /dev/null 2>&1 &&
  ok || fail "sim on the plotter"
[ ! -e "$work/plotter/z.svg" ] && [ ! -e "$work/plotter/z.png" ] && ok || fail "the plotter got a z plot"
grep -q '>Path — [^<]*wave.json<' "$work/plotter/path.svg" && ok || fail "the plotter's path.svg is not the 2-D path"
grep -q 'isometric\|axis-arrows' "$work/plotter/path.svg" && fail "the plotter's path.svg is 3-D" || ok

echo "plot3d: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
