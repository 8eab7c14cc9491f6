# GPIO on a real kernel (runs inside the VM; helpers from sim/vm/vm_lib.sh; docs/gpio.md).
# pathstream_gpio_vm_driver runs a simulated plotter whose lines are gpio-sim lines, mapped by
# the machine profile gpio_vm_profile.json (chip by label, lines by name and offset):
#   line 0 pen-lift (out), 1 enable (out), 2 estop (in, active high),
#   3 limit-x = x- (in, active high), 4 limit-y = y+ (in, active low: pulled up = released).
# The script presses the e-stop through the sim's pull attribute; the limit switches are played
# by the driver's own axes (sim::MachineSwitches on the sim's pull attributes). The outputs are
# checked through the sim's value attributes; gpioget/gpioset cross-check the levels.
chip=$GPIO_SIM_CHIP
sim=$GPIO_SIM_SYSFS
profile=/pathstream/data/gpio_vm_profile.json
value() { cat "$sim/sim_gpio$1/value"; }
released() {
  echo pull-down > "$sim/sim_gpio2/pull"
  echo pull-down > "$sim/sim_gpio3/pull"
  echo pull-up > "$sim/sim_gpio4/pull"
}
released

# Cross-check first: gpioget reads what the driver will read (raw levels, and -l for the
# active-low limit-y), gpioset drives an output the sim sees.
[ "$(timeout -s KILL 10 gpioget "$chip" 2)" = 0 ] || vm_fail "gpioget estop: not released"
[ "$(timeout -s KILL 10 gpioget -l "$chip" 4)" = 0 ] || vm_fail "gpioget -l limit-y: not released"
echo pull-down > "$sim/sim_gpio4/pull"
[ "$(timeout -s KILL 10 gpioget -l "$chip" 4)" = 1 ] || vm_fail "gpioget -l limit-y pulled down: not active"
echo pull-up > "$sim/sim_gpio4/pull"
timeout -s KILL 20 gpioset --mode=signal "$chip" 1=1 &
set_pid=$!
vm_wait 10 sh -c "[ \"\$(cat $sim/sim_gpio1/value)\" = 1 ]" || vm_fail "gpioset enable=1 not seen by the sim"
kill "$set_pid"
wait "$set_pid"
vm_log "gpio: gpioget/gpioset agree with the sim's pull and value attributes"

# The backend's errors on the real chip name chip and line (label lookup included).
vm_run pathstream_gpio_vm_driver errors pathstream-sim > errors.out || { cat errors.out; vm_fail "backend errors"; }
cat errors.out

# Starts the driver in the background (extra arguments: switches its axes play).
start_driver() {
  name=$1
  shift
  rm -rf "$name"; mkdir -p "$name"
  timeout -s KILL 60 pathstream_gpio_vm_driver run "$profile" "$name" 30000 "$@" > "$name.out" 2>&1 &
  driver=$!
}
# The driver holds its lines until DIR/done: the script reads them first, then lets it go.
finish_driver() {
  touch "$1/done"
  wait "$driver" || { cat "$1.out"; vm_fail "$1: the driver failed"; }
  cat "$1.out"
}

# 1. E-stop: an edge on the estop line stops the device within a tick and drops enable;
#    releasing it and resetting gives idle (enable stays low).
start_driver estop
vm_wait 20 test -f estop/running || { cat estop.out; vm_fail "estop: the driver did not start running"; }
[ "$(value 1)" = 1 ] || vm_fail "estop: enable is not high while running"
[ "$(value 0)" = 1 ] || vm_fail "estop: pen is not down while drawing"
# The lines are the driver's now: gpioget cannot take them (the kernel says busy).
! timeout -s KILL 10 gpioget "$chip" 1 2>/dev/null || vm_fail "estop: gpioget could take the enable line"
echo pull-up > "$sim/sim_gpio2/pull"
vm_wait 10 test -f estop/estop || { cat estop.out; vm_fail "no e-stop after the estop edge"; }
[ "$(value 1)" = 0 ] || vm_fail "enable still high in e-stop"
[ "$(value 0)" = 0 ] || vm_fail "pen still down in e-stop"
echo pull-down > "$sim/sim_gpio2/pull"
vm_wait 10 test -f estop/reset || { cat estop.out; vm_fail "no reset after the release"; }
[ "$(value 1)" = 0 ] || vm_fail "enable high after reset (idle)"
finish_driver estop
grep -q 'setpoint repeated: yes' estop.out || vm_fail "the e-stop tick moved"
grep -q 'reaction 1 tick' estop.out || vm_fail "the e-stop took more than one tick"

# 2. Limit switch x- (active high), closed by the x axis itself at -15 mm on its way out to
#    -20 mm: fault naming axis and side, enable low, the switch still closed where x stopped.
start_driver limitx x-=-15
vm_wait 20 test -f limitx/fault || { cat limitx.out; vm_fail "no fault from the x- switch"; }
[ "$(value 1)" = 0 ] || vm_fail "enable still high after the limit fault"
[ "$(value 0)" = 0 ] || vm_fail "pen still down after the limit fault"
[ "$(value 3)" = 1 ] || vm_fail "the x- line is not high where x stopped"
finish_driver limitx
grep -q 'fault: limit switch x- (axis 0, negative side)' limitx.out || vm_fail "wrong fault for x-"
grep -q 'switch x- at -15 mm played by axis 0' limitx.out || vm_fail "the driver did not place x-"
released

# 3. Limit switch y+ (active low: the axis pulls the line down at +12 mm and beyond), reached on
#    the second leg, after x went out and back.
start_driver limity y+=12
vm_wait 20 test -f limity/fault || { cat limity.out; vm_fail "no fault from the y+ switch"; }
[ "$(value 4)" = 0 ] || vm_fail "the active-low y+ line is not low where y stopped"
finish_driver limity
grep -q 'fault: limit switch y+ (axis 1, positive side)' limity.out || vm_fail "wrong fault for y+"
released

# 4. The e-stop reaction in microseconds: the driver writes the estop pull itself and times
#    the write to the enable line going low, 20 times.
vm_run -t 60 pathstream_gpio_vm_driver measure "$profile" "$sim/sim_gpio2/pull" 20 > measure.out || {
  cat measure.out; vm_fail "measure failed"; }
cat measure.out
vm_log "gpio: e-stop, limit switches x- and y+, enable and pen through libgpiod on gpio-sim"
