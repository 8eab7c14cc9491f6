#!/usr/bin/env bash
# ctest: the insn_count plugin's lo=/hi= range, checked on the budget image's calibration
# loop, budget_calibrate(1000), which executes exactly 2 * 1000 + 1 instructions.
#   plugin_selftest.sh NM QEMU BOARD IMAGE PLUGIN
set -uo pipefail
nm=$1 qemu=$2 board=$3 image=$4 plugin=$5
here=$(cd "$(dirname "$0")" && pwd)
read -r addr size < <("$nm" -S "$image" | awk '$4 == "budget_calibrate" {print $1, $2}')
[ -n "${addr:-}" ] || { echo "FAIL: budget_calibrate not in $image"; exit 1; }
lo=$(( 0x$addr & ~1 ))
hi=$(( lo + 0x$size ))
out=$(mktemp)
trap 'rm -f "$out"' EXIT
bash "$here/run_qemu.sh" "$qemu" "$board" "$image" -plugin "$plugin,lo=$lo,hi=$hi,out=$out" >/dev/null
status=$?
cat "$out" | grep -v ' mark '
[ $status -eq 0 ] || { echo "FAIL: image exited with $status"; exit 1; }
count=$(awk '$2 == "range" && $3 == "0" {print $6}' "$out")
total=$(awk '$2 == "total" {print $3}' "$out")
[ "$count" = "2001" ] || { echo "FAIL: counted ${count:-nothing} in budget_calibrate, expected 2001"; exit 1; }
[ "${total:-0}" -gt 100000 ] || { echo "FAIL: implausible total ${total:-none}"; exit 1; }
echo "OK: plugin counted exactly 2001 instructions in [$lo, $hi), $total in total"
