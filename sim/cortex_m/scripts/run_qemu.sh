#!/usr/bin/env bash
# Runs one bare-metal image under qemu-system-arm with semihosting, the way every Cortex-M
# test does. Semihosting output (and qemu's own messages) go to stdout; the exit status is
# the image's (0 = SYS_EXIT with ADP_Stopped_ApplicationExit), 124 on the 60 s timeout.
#   run_qemu.sh QEMU BOARD IMAGE [extra qemu args...]
set -uo pipefail
qemu=$1 board=$2 image=$3
shift 3
exec timeout 60 "$qemu" -M "$board" -semihosting-config enable=on,target=native \
  -nographic -monitor none -serial none -kernel "$image" "$@" 2>&1
