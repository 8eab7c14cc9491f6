# VM self-test, GPIO (runs inside the VM; helpers from sim/vm/vm_lib.sh). libgpiod's C API
# (vm_selftest) and the gpiod tools against the gpio-sim chip that /init created.
chip=$GPIO_SIM_CHIP
sim=$GPIO_SIM_SYSFS
vm_log "gpio-sim chip $chip, simulator attributes in $sim"

vm_run gpiodetect > detect.out || vm_fail "gpiodetect"
grep -q "^$chip \[pathstream-sim\] (16 lines)" detect.out || vm_fail "gpiodetect: $(cat detect.out)"
vm_run gpioinfo "$chip" > info.out || vm_fail "gpioinfo"
grep -q '"estop"' info.out || vm_fail "gpioinfo shows no line named estop"
[ "$(gpiofind estop)" = "$chip 2" ] || vm_fail "gpiofind estop: $(gpiofind estop)"

vm_expect 0 vm_selftest gpio "$GPIO_SIM_CHIP_PATH" "$sim"

# gpioset drives "enable" (line 1) high while it runs; the simulator sees the level.
timeout -s KILL 20 gpioset --mode=signal "$chip" 1=1 &
set_pid=$!
vm_wait 10 grep -qx 1 "$sim/sim_gpio1/value" || vm_fail "gpioset 1=1 did not reach sim_gpio1/value"
kill "$set_pid"
wait "$set_pid"
vm_wait 10 grep -qx 0 "$sim/sim_gpio1/value" || vm_fail "line 1 did not fall back to its pull"

# gpioget reads what the simulator's pull says ("limit-x", line 3).
for pull in pull-up:1 pull-down:0; do
  echo "${pull%:*}" > "$sim/sim_gpio3/pull"
  got=$(timeout -s KILL 10 gpioget "$chip" 3)
  [ "$got" = "${pull#*:}" ] || vm_fail "gpioget after ${pull%:*}: '$got'"
done

# gpiomon sees the rising edge the simulator makes on "limit-y" (line 4).
timeout -s KILL 20 gpiomon --num-events=1 --rising-edge --format='%e %o' "$chip" 4 > mon.out &
mon=$!
vm_wait 10 sh -c "gpioinfo $chip | grep -q 'line *4:.*\"gpiomon\"'" || vm_fail "gpiomon did not request line 4"
echo pull-up > "$sim/sim_gpio4/pull"
wait "$mon" || vm_fail "gpiomon saw no edge"
grep -qx '1 4' mon.out || vm_fail "gpiomon printed '$(cat mon.out)'"
vm_log "gpio: gpiodetect, gpioinfo, gpiofind, gpioset, gpioget, gpiomon agree with the simulator"
