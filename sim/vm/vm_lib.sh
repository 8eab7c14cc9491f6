# Helpers for test scripts inside the pathstream test VM (busybox sh). /init sources this file
# before the test script, so every function here is available to it (docs/vm.md).
#
#   vm_run [-t SECS] CMD [ARGS...]   run CMD with a timeout (default $VM_PROGRAM_TIMEOUT s),
#                                    killed with SIGKILL when it expires; logs the command, its
#                                    exit status and the time taken; returns CMD's status
#                                    (137 when the timeout killed it)
#   vm_expect RC CMD [ARGS...]       vm_run CMD and fail the test unless it exits with RC
#   vm_expect_out RC FILE CMD [ARGS...]
#                                    vm_expect with CMD's stdout and stderr in FILE, which is
#                                    printed before the failure when the status differs
#   vm_wait SECS CMD [ARGS...]       poll CMD every 0.1 s until it succeeds; 1 after SECS
#   vm_fail MESSAGE...               print "PATHSTREAM-VM: FAIL: MESSAGE" and exit 1
#   vm_log MESSAGE...                print "PATHSTREAM-VM: MESSAGE"
# Their messages go to file descriptor 9, the console's stderr as it was when this file was
# sourced: `vm_run prog > out 2>&1` and `vm_expect 0 prog > out 2>&1 || ...` capture only
# prog's output, and a vm_fail inside them still reaches the console and the host's log (it
# once went into the redirected file, and a failing test said nothing but rc=1).
#   vm_uptime                        seconds since boot, e.g. 4.87
#
# Environment: VM_PROGRAM_TIMEOUT, VM_CAN_IFACES (e.g. "vcan0") when CAN is up, and with the
# gpio-sim chip GPIO_SIM_CHIP (gpiochipN), GPIO_SIM_CHIP_PATH (/dev/gpiochipN) and
# GPIO_SIM_SYSFS (the directory holding sim_gpioN/value and sim_gpioN/pull).
# Given programs are in /pathstream/bin (on PATH), data files in /pathstream/data; the
# working directory is /pathstream/work (writable).

exec 9>&2

vm_log() { echo "PATHSTREAM-VM: $*" >&9; }
vm_fail() {
  echo "PATHSTREAM-VM: FAIL: $*" >&9
  exit 1
}
vm_uptime() { cut -d' ' -f1 /proc/uptime; }

vm_run() {
  _vm_t=$VM_PROGRAM_TIMEOUT
  if [ "$1" = "-t" ]; then
    _vm_t=$2
    shift 2
  fi
  _vm_start=$(vm_uptime)
  timeout -s KILL "$_vm_t" "$@"
  _vm_rc=$?
  _vm_end=$(vm_uptime)
  if [ "$_vm_rc" = 137 ]; then
    echo "PATHSTREAM-VM: run: $* -> killed (timeout $_vm_t s?) after $(echo "$_vm_end $_vm_start" | awk '{printf "%.2f", $1 - $2}') s" >&9
  else
    echo "PATHSTREAM-VM: run: $* -> rc=$_vm_rc in $(echo "$_vm_end $_vm_start" | awk '{printf "%.2f", $1 - $2}') s" >&9
  fi
  return "$_vm_rc"
}

vm_expect() {
  _vm_want=$1
  shift
  vm_run "$@"
  _vm_got=$?
  [ "$_vm_got" = "$_vm_want" ] || vm_fail "$* exited with $_vm_got, expected $_vm_want"
}

vm_expect_out() {
  _vm_want=$1
  _vm_file=$2
  shift 2
  vm_run "$@" > "$_vm_file" 2>&1
  _vm_got=$?
  if [ "$_vm_got" != "$_vm_want" ]; then
    cat "$_vm_file" >&9
    vm_fail "$* exited with $_vm_got, expected $_vm_want (output above, from $_vm_file)"
  fi
}

vm_wait() {
  _vm_n=$(awk -v s="$1" 'BEGIN { printf "%d", s * 10 }')
  shift
  while [ "$_vm_n" -gt 0 ]; do
    "$@" >/dev/null 2>&1 && return 0
    usleep 100000
    _vm_n=$((_vm_n - 1))
  done
  return 1
}
