#!/bin/sh
# Runs every fuzz target for a bounded time from its seed corpus (fuzz/corpus/<target>/) and
# prints the executions each made. New inputs go to a scratch directory, never into the repo;
# a crash or a broken property leaves its reproducer there and makes the script fail.
#
# Usage: fuzz/run.sh [SECONDS_PER_TARGET] [BUILD_DIR]
#   SECONDS_PER_TARGET  default $PATHSTREAM_FUZZ_SECONDS, else 5 (what the tests fuzz.<name> run)
#   BUILD_DIR           the tree configured with the preset asan (default build/asan)
# Environment: FUZZ_TARGETS="json_path csv_path" runs only those; FUZZ_WORK=DIR keeps the
# scratch corpora and reproducers there (default: a temporary directory, kept on failure);
# FUZZ_RUNS=N also stops each target after N executions (whichever comes first).
set -u
here=$(cd "$(dirname "$0")" && pwd)
seconds=${1:-${PATHSTREAM_FUZZ_SECONDS:-5}}
build=${2:-$here/../build/asan}
targets=${FUZZ_TARGETS:-"json_path csv_path svg_path gcode_path machine_profile target_url modbus_map modbus_rtu_slave wire_spans can_node cia402_drive job_journal http_request tool_table function_curve bpt_path"}
work=${FUZZ_WORK:-$(mktemp -d)}
failed=""
for t in $targets; do
    exe=$(find "$build" -name "fuzz_$t" -type f -perm -u+x | head -n 1)
    if [ -z "$exe" ]; then
        echo "fuzz_$t: not built in $build (cmake --preset asan && cmake --build --preset asan)" >&2
        failed="$failed $t"
        continue
    fi
    mkdir -p "$work/$t"
    log="$work/$t.log"
    dict=""
    [ -f "$here/dict/$t.dict" ] && dict="-dict=$here/dict/$t.dict"
    # -rss_limit_mb: a reader is allowed what a big drawing needs, not unbounded memory.
    runs_cap=""
    [ -n "${FUZZ_RUNS:-}" ] && runs_cap="-runs=$FUZZ_RUNS"
    "$exe" -max_total_time="$seconds" $runs_cap -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
        -artifact_prefix="$work/$t-" $dict "$work/$t" "$here/corpus/$t" >"$log" 2>&1
    status=$?
    runs=$(sed -n 's/^Done \([0-9]*\) runs in \([0-9]*\) second.*/\1 executions in \2 s/p' "$log")
    if [ $status -ne 0 ]; then
        echo "fuzz_$t: FAILED (exit $status), see $log"
        grep -E "property violated|ERROR: |runtime error" "$log" | head -n 3
        failed="$failed $t"
    else
        echo "fuzz_$t: ${runs:-no summary}, corpus $(ls "$work/$t" | wc -l) new inputs"
    fi
done
if [ -n "$failed" ]; then
    echo "failed:$failed (reproducers and logs in $work)"
    exit 1
fi
[ -z "${FUZZ_WORK:-}" ] && rm -rf "$work"
exit 0
