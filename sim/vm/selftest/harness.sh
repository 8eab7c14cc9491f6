# VM self-test of the harness's own contract (runs inside the VM; helpers from vm_lib.sh).
# Registered with EXPECT_RC 7 and PROGRAM_TIMEOUT 2: the script's exit status must reach the
# host, vm_run must kill a program at the per-program timeout, data files must be there.
[ -f /pathstream/data/harness-data.txt ] || vm_fail "no data file in /pathstream/data"
grep -qx 'pathstream vm data file' /pathstream/data/harness-data.txt || vm_fail "data file content"
[ -x /pathstream/bin/vm_selftest ] || vm_fail "vm_selftest not in /pathstream/bin"
vm_selftest 2>/dev/null
[ $? = 2 ] || vm_fail "vm_selftest without arguments should print usage and exit 2"

start=$(vm_uptime)
vm_run sleep 30
rc=$?
[ "$rc" = 137 ] || vm_fail "vm_run sleep 30 with a 2 s timeout returned $rc, expected 137"
took=$(echo "$(vm_uptime) $start" | awk '{ printf "%d", $1 - $2 }')
[ "$took" -lt 10 ] || vm_fail "the per-program timeout took $took s"
vm_run -t 5 true || vm_fail "vm_run -t 5 true failed"
[ "$(vm_run echo captured 2>/dev/null)" = captured ] || vm_fail "vm_run must not mix its log into stdout"
! grep -q vcan /proc/modules || vm_fail "NO_CAN: CAN modules should not be loaded"
vm_log "harness: data files, programs, per-program timeout, exit status all as documented"
exit 7
