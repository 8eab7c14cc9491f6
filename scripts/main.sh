#!/usr/bin/env bash
# The main job: build pathstream (incrementally) and run a path through the exact core.
#   scripts/main.sh                      # examples/rose.json -> out/rose.csv
#   scripts/main.sh setpoints FILE ...   # any pathstream command line
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh >/dev/null
if [ ! -f build/default/CMakeCache.txt ]; then
  cmake --preset default >/dev/null
fi
cmake --build --preset default --target pathstream >/dev/null
if [ $# -eq 0 ]; then
  mkdir -p out
  set -- setpoints examples/rose.json --ticks-per-span 32 --out out/rose.csv
fi
exec build/default/host/pathstream "$@"
