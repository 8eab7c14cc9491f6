#!/bin/sh
# /init of the pathstream test VM (busybox sh, PID 1). Written into the initramfs by
# run_in_vm.py, with /etc/pathstream-vm/config and /etc/pathstream-vm/modules beside it.
# Mounts the pseudo file systems, loads the modules, brings up vcan0, creates the gpio-sim
# chip when asked, runs /pathstream/test.sh under a timeout, prints the one result line that
# the host looks for, and powers off. Nothing here may block without a timeout.
export PATH=/pathstream/bin:/usr/bin:/bin:/sbin
export HOME=/root
umask 022

result() {
  echo "PATHSTREAM-VM-RESULT rc=$1"
  sync
  poweroff -f
  sleep 5
  echo "PATHSTREAM-VM: poweroff failed" # the host's timeout ends the VM
  exec sleep 3600
}
die() {
  echo "PATHSTREAM-VM: setup failed: $*"
  result 200
}

mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev 2>/dev/null
mkdir -p /tmp /run /root
mount -t tmpfs tmpfs /tmp
mount -t tmpfs tmpfs /run

. /etc/pathstream-vm/config

echo "PATHSTREAM-VM: kernel $(uname -r) at $(cut -d' ' -f1 /proc/uptime) s"

while read -r m; do
  [ -n "$m" ] || continue
  insmod "/lib/modules/$(uname -r)/$m" || die "insmod $m"
done < /etc/pathstream-vm/modules
# Out-of-tree modules taint the kernel with a warning: keep the console for our output.
dmesg -n 1 2>/dev/null

if [ -d /sys/kernel/config ] && grep -q configfs /proc/filesystems; then
  mount -t configfs configfs /sys/kernel/config || die "mount configfs"
fi

: > /run/pathstream-vm.env
if [ "$VM_CAN" = 1 ]; then
  for i in $VM_CAN_IFACES; do
    ip link add dev "$i" type vcan || die "ip link add $i type vcan"
    ip link set "$i" up || die "ip link set $i up"
  done
  echo "export VM_CAN_IFACES='$VM_CAN_IFACES'" >> /run/pathstream-vm.env
fi

if [ "$VM_GPIO_SIM" = 1 ]; then
  cfg=/sys/kernel/config/gpio-sim/pathstream-sim
  mkdir "$cfg" || die "mkdir $cfg (is gpio-sim loaded?)"
  mkdir "$cfg/bank0" || die "mkdir $cfg/bank0"
  echo "$VM_GPIO_SIM_LINES" > "$cfg/bank0/num_lines" || die "num_lines"
  echo pathstream-sim > "$cfg/bank0/label" || die "label"
  n=0
  for name in $VM_GPIO_SIM_NAMES; do
    mkdir "$cfg/bank0/line$n" && echo "$name" > "$cfg/bank0/line$n/name" || die "line$n name"
    n=$((n + 1))
  done
  echo 1 > "$cfg/live" || die "gpio-sim live"
  dev=$(cat "$cfg/dev_name")
  chip=$(cat "$cfg/bank0/chip_name")
  [ -c "/dev/$chip" ] || die "no /dev/$chip"
  {
    echo "export GPIO_SIM_CHIP=$chip"
    echo "export GPIO_SIM_CHIP_PATH=/dev/$chip"
    echo "export GPIO_SIM_SYSFS=/sys/devices/platform/$dev/$chip"
  } >> /run/pathstream-vm.env
fi
. /run/pathstream-vm.env

echo "PATHSTREAM-VM: ready at $(cut -d' ' -f1 /proc/uptime) s; running test.sh"
cd /pathstream/work 2>/dev/null || cd /tmp
timeout -s KILL "$VM_SCRIPT_TIMEOUT" sh -c '. /pathstream/vm_lib.sh; . /pathstream/test.sh'
rc=$?
[ "$rc" = 137 ] && echo "PATHSTREAM-VM: test.sh killed after $VM_SCRIPT_TIMEOUT s"
echo "PATHSTREAM-VM: done at $(cut -d' ' -f1 /proc/uptime) s"
result "$rc"
