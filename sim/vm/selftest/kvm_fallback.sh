#!/usr/bin/env bash
# Host-side test of the harness's accelerator choice: with PATHSTREAM_VM_KVM_ACCEL naming an
# -accel option qemu cannot start, the harness must say so in one line, run the VM under TCG
# and pass; a second run must take the cached verdict instead of probing again.
#   kvm_fallback.sh RUNNER KERNEL_CACHE WORK HARNESS_SCRIPT VM_SELFTEST DATA_FILE HANG_SCRIPT
set -uo pipefail
runner=$1 kernel_cache=$2 work=$3 script=$4 program=$5 data=$6 hang=$7
rm -rf "$work"
mkdir -p "$work"
cache=$work/cache  # its own verdict cache, so this run really probes
export PATHSTREAM_VM_KVM_ACCEL="kvm,pathstream-cannot-start=on"
fail() { echo "kvm_fallback: FAIL: $*"; exit 1; }

/usr/bin/python3 "$runner" --kernel-cache "$kernel_cache" --base-cache "$cache" \
  --work "$work/first" --script "$script" --program "$program" --data "$data" \
  --no-can --program-timeout 2 --timeout 60 --expect-rc 7 --quiet >"$work/first.log" 2>&1
rc=$?
cat "$work/first.log"
[ "$rc" = 0 ] || fail "the run under the TCG fallback did not pass (harness exit $rc)"
n=$(grep -c "^run_in_vm: accelerator: KVM (-accel kvm,pathstream-cannot-start=on) cannot start the guest: qemu exited with .*; using TCG" "$work/first.log")
[ "$n" = 1 ] || fail "expected exactly one line saying KVM cannot start and TCG is used, got $n"
grep -q "^run_in_vm: booting .* -accel tcg " "$work/first.log" || fail "the test VM was not booted with -accel tcg"
grep -q '"accel": "tcg"' "$cache/accel-verdict.json" || fail "no TCG verdict cached in $cache/accel-verdict.json"

# The second run (a script that never ends, killed by the overall timeout of 2 s) reads the
# verdict and probes nothing.
/usr/bin/python3 "$runner" --kernel-cache "$kernel_cache" --base-cache "$cache" \
  --work "$work/second" --script "$hang" --no-can --quiet --timeout 2 --expect-rc 124 \
  >"$work/second.log" 2>&1
rc=$?
cat "$work/second.log"
[ "$rc" = 0 ] || fail "second run: harness exit $rc"
grep -q "^run_in_vm: accelerator: TCG (cached verdict: -accel kvm,pathstream-cannot-start=on failed" \
  "$work/second.log" || fail "the second run did not use the cached verdict"
! grep -q "cannot start the guest" "$work/second.log" || fail "the second run probed again"
echo "kvm_fallback: KVM failure detected, TCG fallback passed, verdict cached and reused"
