#!/usr/bin/env bash
# Runs the timing-sensitive tests N times in a row beside a CPU hog on every core and reports
# each test's failures. A test that fails here fails under load somewhere: that is a defect to
# fix, not a run to repeat (README.md, "Stress runs").
#
#   scripts/stress_tests.sh [N] [options]       N rounds (default 20)
#     --build-dir DIR     the build to test (default build/default; built first, not configured)
#     --tests REGEX       ctest -R regex of the tests to run (default: the set below)
#     --hogs K            CPU hogs (default: one per core, nproc)
#
# The default set: every VM test (ctest label vm: SocketCAN, gpio-sim, CiA 402), the operator,
# event and jerk-stream CLI tests, the resume and ctl-link cases of host_tests (Catch2 tags
# [resume], [threads] cases that stream to a served device), the core's two-thread stop-while-idle
# case, and the browser test.
# Each round's ctest output is kept in BUILD/stress/round-K.log; the table at the end gives
# runs, failures and the rounds that failed for every test, and the exit status is 1 when any
# run failed. The rounds run one test at a time (ctest -j1): the hogs are the load.
set -uo pipefail
cd "$(dirname "$0")/.."

rounds=20
build=build/default
regex='\.vm$|^cli_operator$|^cli_events$|^cli_jerk_stream$|^browser_serve$|^resume|^ctl.s link|^pause:|stream.*while|^vm\.selftest|^stop while idle: every'
hogs=$(nproc)
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --tests) regex=$2; shift 2 ;;
    --hogs) hogs=$2; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    [0-9]*) rounds=$1; shift ;;
    *) echo "stress_tests.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$rounds" in ''|*[!0-9]*|0) echo "stress_tests.sh: N must be a positive integer, not '$rounds'" >&2; exit 2 ;; esac
case "$hogs" in ''|*[!0-9]*) echo "stress_tests.sh: --hogs must be a non-negative integer, not '$hogs'" >&2; exit 2 ;; esac
[ -f "$build/CTestTestfile.cmake" ] || {
  echo "stress_tests.sh: $build is not a configured build (cmake --preset default first)" >&2; exit 2; }

echo "stress_tests.sh: building $build"
cmake --build "$build" > /dev/null || { echo "stress_tests.sh: the build failed" >&2; exit 1; }
mapfile -t tests < <(ctest --test-dir "$build" -N -R "$regex" | sed -n -E 's/^ *Test +#[0-9]+: (.*)$/\1/p')
[ ${#tests[@]} -gt 0 ] || { echo "stress_tests.sh: no test in $build matches '$regex'" >&2; exit 2; }
echo "stress_tests.sh: ${#tests[@]} tests x $rounds rounds beside $hogs CPU hogs"

hog_pids=()
stop_hogs() {
  [ ${#hog_pids[@]} -gt 0 ] && kill "${hog_pids[@]}" 2>/dev/null
  wait 2>/dev/null
  hog_pids=()
}
trap 'stop_hogs; exit 130' INT TERM
trap stop_hogs EXIT
for _ in $(seq "$hogs"); do
  # A busy loop in its own shell: one core's worth of runnable work, nothing written anywhere.
  bash -c 'while :; do :; done' &
  hog_pids+=($!)
done

out=$build/stress
rm -rf "$out" && mkdir -p "$out"
declare -A fails runs failed_rounds
for t in "${tests[@]}"; do fails[$t]=0 runs[$t]=0 failed_rounds[$t]=""; done
start=$SECONDS
for r in $(seq "$rounds"); do
  log=$out/round-$r.log
  ctest --test-dir "$build" -R "$regex" -j1 --output-on-failure > "$log" 2>&1
  # ctest's lines: "  12/40 Test  #7: name ......   Passed    3.21 sec" (or ***Failed, ***Timeout...)
  mapfile -t results < <(sed -n -E 's/^ *[0-9]+\/[0-9]+ Test +#[0-9]+: (.*[^ ]) \.+ *(\*\*\*)?([A-Za-z ]+[a-z])[ 0-9.]+sec$/\3\t\1/p' "$log")
  bad=()
  for line in "${results[@]}"; do
    verdict=${line%%$'\t'*} name=${line#*$'\t'}
    runs[$name]=$(( ${runs[$name]:-0} + 1 ))
    if [ "$verdict" != Passed ]; then
      fails[$name]=$(( ${fails[$name]:-0} + 1 ))
      failed_rounds[$name]+="$r "
      bad+=("$name ($verdict)")
    fi
  done
  load=$(cut -d' ' -f1 /proc/loadavg)
  if [ ${#bad[@]} -eq 0 ]; then
    echo "round $r/$rounds: ${#results[@]} passed (load $load, $((SECONDS - start)) s)"
  else
    echo "round $r/$rounds: ${#bad[@]} FAILED: ${bad[*]} (load $load; $log)"
  fi
done
stop_hogs

echo
echo "=== stress_tests.sh: $rounds rounds, $hogs hogs, $(( (SECONDS - start) / 60 )) min $(( (SECONDS - start) % 60 )) s ==="
printf '%-60s %5s %6s  %s\n' test runs failed "failed in rounds"
total_fail=0 total_runs=0
for t in "${tests[@]}"; do
  printf '%-60s %5s %6s  %s\n' "${t:0:60}" "${runs[$t]:-0}" "${fails[$t]:-0}" "${failed_rounds[$t]}"
  total_fail=$((total_fail + ${fails[$t]:-0}))
  total_runs=$((total_runs + ${runs[$t]:-0}))
  # A test that never reported (the run was cut short) counts as failed in every round.
  missing=$((rounds - ${runs[$t]:-0}))
  [ "$missing" -gt 0 ] && total_fail=$((total_fail + missing))
done
echo "stress: $((total_runs - total_fail < 0 ? 0 : total_runs - total_fail)) passed, $total_fail failed"
[ "$total_fail" -eq 0 ]
