#!/usr/bin/env bash
# ctest: the workload's checksum on a Cortex-M image must equal the host build's, and both
# must report no self-check mismatches.
#   compare_checksum.sh HOST_PROGRAM QEMU BOARD IMAGE
set -uo pipefail
host_program=$1 qemu=$2 board=$3 image=$4
here=$(cd "$(dirname "$0")" && pwd)

host_out=$("$host_program"); host_status=$?
target_out=$(bash "$here/run_qemu.sh" "$qemu" "$board" "$image"); target_status=$?
echo "host ($(basename "$host_program")), exit $host_status:"
echo "$host_out" | sed 's/^/  /'
echo "$board ($image), exit $target_status:"
echo "$target_out" | sed 's/^/  /'

host_sum=$(echo "$host_out" | grep -E '^checksum=' | head -1)
target_sum=$(echo "$target_out" | grep -E '^checksum=' | head -1)
host_summary=$(echo "$host_out" | grep -E '^workload ' | head -1)
target_summary=$(echo "$target_out" | grep -E '^workload ' | head -1)
[ $host_status -eq 0 ] || { echo "FAIL: host workload failed"; exit 1; }
[ $target_status -eq 0 ] || { echo "FAIL: image exited with $target_status"; exit 1; }
[ -n "$host_sum" ] || { echo "FAIL: no checksum from the host"; exit 1; }
[ "$host_sum" = "$target_sum" ] || { echo "FAIL: checksums differ"; exit 1; }
[ "$host_summary" = "$target_summary" ] || { echo "FAIL: summaries differ"; exit 1; }
echo "OK: $board $host_sum equals the host's"
