#!/usr/bin/env bash
# Builds everything and runs the whole test suite, one CMake workflow preset after another:
#   default  release build with the Cortex-M images under qemu and the real-kernel VM tests
#   asan     AddressSanitizer + UBSan build (clang) of the host tests and the libFuzzer targets;
#            each target is a test, fuzz.<name>, run PATHSTREAM_FUZZ_SECONDS (default 5) from
#            its seed corpus (docs/fuzzing.md)
#   tsan     ThreadSanitizer build of the test cases that run threads (Catch2 tag [threads])
# Every preset runs even when an earlier one failed; a summary of all of them comes last, and
# the exit status is non-zero when any failed. A failed test fails its preset: nothing is run
# again. A test that fails only under load is a defect; scripts/stress_tests.sh runs the
# timing-sensitive ones beside a CPU hog per core to find such tests (README.md, "Stress runs").
#   scripts/test.sh                 # what CI runs: every preset
#   scripts/test.sh --quick         # the default preset only
#   scripts/test.sh asan tsan       # the named presets only
# Each preset's whole output is also kept in build/PRESET.log.
set -uo pipefail
cd "$(dirname "$0")/.."

all_presets=(default asan tsan)
if [ "${1:-}" = "--quick" ]; then
  presets=(default)
elif [ $# -gt 0 ]; then
  presets=("$@")
  for p in "${presets[@]}"; do
    case " ${all_presets[*]} " in
      *" $p "*) ;;
      *) echo "test.sh: unknown preset '$p' (presets: ${all_presets[*]}; or --quick)" >&2; exit 2 ;;
    esac
  done
else
  presets=("${all_presets[@]}")
fi

scripts/setup.sh || { echo "test.sh: scripts/setup.sh failed: nothing was built" >&2; exit 1; }
mkdir -p build

declare -A status seconds passed failed total
start_all=$SECONDS
for p in "${presets[@]}"; do
  echo "=== test.sh: preset $p: configure, build, test ==="
  t0=$SECONDS
  cmake --workflow --preset "$p" 2>&1 | tee "build/$p.log"
  status[$p]=${PIPESTATUS[0]}
  seconds[$p]=$((SECONDS - t0))
  # ctest's closing line: "100% tests passed, 0 tests failed out of 307"
  line=$(grep -E '^[0-9]+% tests passed, [0-9]+ tests? failed out of [0-9]+' "build/$p.log" | tail -1)
  if [ -n "$line" ]; then
    total[$p]=$(sed -E 's/.* out of ([0-9]+).*/\1/' <<<"$line")
    failed[$p]=$(sed -E 's/.*passed, ([0-9]+) tests? failed.*/\1/' <<<"$line")
    passed[$p]=$((total[$p] - failed[$p]))
  else
    total[$p]=0 failed[$p]=0 passed[$p]=0  # it stopped before testing (configure or build)
  fi
done

echo
echo "=== test.sh: summary ($(( (SECONDS - start_all) / 60 )) min $(( (SECONDS - start_all) % 60 )) s) ==="
printf '%-9s %-8s %8s %8s %8s %10s\n' preset result tests passed failed "wall (s)"
sum_passed=0 sum_failed=0 any_failed=0
for p in "${presets[@]}"; do
  if [ "${status[$p]}" = 0 ]; then
    result=ok
  else
    any_failed=1
    if [ "${total[$p]}" = 0 ]; then result="FAILED (before the tests: see build/$p.log)"; else result=FAILED; fi
    # A preset that failed with no failed test (configure, build, no tests found) counts as
    # one failure in the closing line.
    [ "${failed[$p]}" = 0 ] && failed[$p]=1
  fi
  printf '%-9s %-8s %8s %8s %8s %10s\n' "$p" "$result" "${total[$p]}" "${passed[$p]}" \
    "${failed[$p]}" "${seconds[$p]}"
  if [ "${status[$p]}" != 0 ] && [ "${total[$p]}" != 0 ]; then
    sed -n -E 's/^[[:space:]]*[0-9]+ - (.*) \((Failed|Timeout|SEGFAULT|Subprocess aborted|Child aborted|Exception)\)$/          failed: \1 (\2)/p' "build/$p.log"
  fi
  sum_passed=$((sum_passed + passed[$p]))
  sum_failed=$((sum_failed + failed[$p]))
done
echo "test.sh: $sum_passed passed, $sum_failed failed"
exit $any_failed
