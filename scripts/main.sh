#!/usr/bin/env bash
# The main job: build pathstream (incrementally), plan an example drawing for a pen plotter
# and run it on the simulated plotter: a report on screen, plots in out/rose/.
#   scripts/main.sh                  # examples/rose.json on examples/machines/pen_plotter.json
#   scripts/main.sh COMMAND ARGS...  # any pathstream command line (pathstream --help)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh >/dev/null
if [ ! -f build/default/CMakeCache.txt ]; then
  cmake --preset default >/dev/null
fi
cmake --build --preset default --target pathstream >/dev/null
if [ $# -eq 0 ]; then
  mkdir -p out
  set -- sim examples/rose.json --machine examples/machines/pen_plotter.json --plot out/rose
fi
exec build/default/host/pathstream "$@"
