#!/usr/bin/env bash
# Prints the Cortex-M instruction-budget tables (Markdown) for the README and docs:
# Cortex-M4, Cortex-M0+, and Cortex-M4 with the portable C++ step for comparison.
#   sim/cortex_m/report_budget.sh [BUILD_DIR]     (default: build/default, else build/cortexm)
# Needs a build of the main project with PATHSTREAM_CORTEX_M=ON. Counts, not time: the
# figures are identical on every run and every machine.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-}
if [ -z "$build" ]; then
  for candidate in "$repo/build/default" "$repo/build/cortexm"; do
    [ -x "$candidate/sim/cortex_m/cortex_m_budget" ] && { build=$candidate; break; }
  done
fi
cm=${build:?no build directory with sim/cortex_m found; pass one}/sim/cortex_m
for f in "$cm/cortex_m_budget" "$cm/libpathstream_insn_count.so" "$cm/m4/budget.elf" \
         "$cm/m0plus/budget.elf" "$cm/m4_portable/budget.elf"; do
  [ -e "$f" ] || { echo "report_budget.sh: $f missing: build $build first" >&2; exit 2; }
done
qemu=$(command -v qemu-system-arm) || { echo "qemu-system-arm not found: run scripts/setup.sh" >&2; exit 2; }
nm=$(command -v arm-none-eabi-nm) || { echo "arm-none-eabi-nm not found: run scripts/setup.sh" >&2; exit 2; }
common=(--qemu "$qemu" --plugin "$cm/libpathstream_insn_count.so" --nm "$nm")
status=0
"$cm/cortex_m_budget" "${common[@]}" --board mps2-an386 --label "Cortex-M4" \
  --image "$cm/m4/budget.elf" --budget 20 || status=1
"$cm/cortex_m_budget" "${common[@]}" --board microbit \
  --label "Cortex-M0+ (cortex-m0plus code; qemu models an M0, same ARMv6-M instructions)" \
  --image "$cm/m0plus/budget.elf" --budget 48 --no-legend || status=1
"$cm/cortex_m_budget" "${common[@]}" --board mps2-an386 \
  --label "Cortex-M4 with PATHSTREAM_PORTABLE_STEP (C++ step instead of the Thumb-2 asm)" \
  --image "$cm/m4_portable/budget.elf" --budget 20 --no-legend || status=1
exit $status
