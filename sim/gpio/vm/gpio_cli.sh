# `pathstream device --machine` on a real kernel's gpio-sim (runs inside the VM; helpers from
# sim/vm/vm_lib.sh; docs/gpio.md). The CLI opens the profile's lines through libgpiod:
#   line 0 pen (out), 1 enable (out), 2 estop (in), 3 limit-x = x- (in), 4 limit-y = y+ (in,
#   active low). The script plays the machine's switches through the sim's pull attributes.
# 1. A drawing streamed over vcan0 runs with enable high and the pen down on real lines; the
#    e-stop line stops it; the streamer exits 6 naming the e-stop, enable and pen drop.
# 2. --home with a switch that never closes: exit 6, "not found within 1.000 mm".
# 3. --home with the switch played from the device's own phase log: search, back-off, latch,
#    pull-off, homed; then it serves, and the re-armed x- switch faults by name.
# 4. `ctl home` and `ctl pen` over CAN while the device serves: the same homing, the pen line.
sim=$GPIO_SIM_SYSFS
data=/pathstream/data
profile=$data/gpio_vm_profile.json
iface=vcan0
value() { cat "$sim/sim_gpio$1/value"; }
pull() { echo "$2" > "$sim/sim_gpio$1/pull"; }
released() { pull 2 pull-down; pull 3 pull-down; pull 4 pull-up; }
rx_ready() { [ "$(grep -c "^ *$iface " /proc/net/can/rcvlist_all)" -ge "$1" ]; }
line_is() { [ "$(cat "$sim/sim_gpio$1/value")" = "$2" ]; }
logged() { grep -q "$1" "$2"; }
released

# 1. Stream + e-stop. Quarter speed: the 1.7 s drawing takes 6.8 s, time to act mid-stroke.
timeout -s KILL 40 pathstream device -m "$profile" --can "$iface" --node 3 --time-scale 0.25 > dev1.out 2>&1 &
dev=$!
vm_wait 10 rx_ready 1 || { cat dev1.out; vm_fail "the device did not open $iface"; }
logged "GPIO chip pathstream-sim: enable=enable pen=0 estop=estop x-=limit-x y+=limit-y (active low)" dev1.out ||
  { cat dev1.out; vm_fail "the device did not report its GPIO lines"; }
[ "$(value 1)" = 0 ] || vm_fail "enable high while idle"
timeout -s KILL 40 pathstream stream "$data/wave.json" -m "$profile" -t "can://$iface?node=3&protocol=native" \
  --link-timeout 5 > stream1.out 2>&1 &
streamer=$!
vm_wait 15 line_is 1 1 || { cat dev1.out stream1.out; vm_fail "enable did not go high while streaming"; }
vm_wait 10 line_is 0 1 || { cat dev1.out stream1.out; vm_fail "the pen never went down"; }
vm_log "gpio cli: streaming with enable high and the pen down"
pull 2 pull-up
wait "$streamer"
rc=$?
cat stream1.out
[ "$rc" = 6 ] || vm_fail "the streamer exited $rc after the e-stop, expected 6"
logged "device stopped in e-stop" stream1.out || vm_fail "the streamer did not name the e-stop"
vm_wait 5 logged "E-STOP at tick" dev1.out || { cat dev1.out; vm_fail "the device did not log the e-stop"; }
[ "$(value 1)" = 0 ] || vm_fail "enable still high in e-stop"
[ "$(value 0)" = 0 ] || vm_fail "pen still down in e-stop"
kill -INT "$dev"
wait "$dev" || { cat dev1.out; vm_fail "the device failed"; }
cat dev1.out
pull 2 pull-down

# 2. Homing against a switch that never closes within max_travel.
sed 's/"max_travel": 100/"max_travel": 1/' "$profile" > short.json
vm_expect_out 6 dev2.out pathstream device -m short.json --home --can "$iface" --exit-after 5
cat dev2.out
logged "homing x: switch x- not found within 1.000 mm (max_travel)" dev2.out || vm_fail "wrong homing error"
[ "$(value 1)" = 0 ] || vm_fail "enable high after a failed homing"

# 3. Homing with the switch played from the device's phase log, then serving.
timeout -s KILL 60 pathstream device -m "$profile" --home --can "$iface" --node 3 > dev3.out 2>&1 &
dev=$!
vm_wait 10 logged "x: searching" dev3.out || { cat dev3.out; vm_fail "homing did not start"; }
vm_wait 5 line_is 1 1 || vm_fail "enable not high while homing"
usleep 300000
pull 3 pull-up  # the axis reaches x-
vm_wait 10 logged "x: backing off" dev3.out || { cat dev3.out; vm_fail "no back-off after the switch closed"; }
pull 3 pull-down  # ... and leaves it
vm_wait 10 logged "x: approaching slowly" dev3.out || { cat dev3.out; vm_fail "no slow approach"; }
usleep 300000
pull 3 pull-up  # the slow approach reaches it again: the latch
vm_wait 10 logged "x: pulling off the switch" dev3.out || { cat dev3.out; vm_fail "no pull-off after the latch"; }
pull 3 pull-down
vm_wait 10 logged "x: homed: switch point = 0.000 mm" dev3.out || { cat dev3.out; vm_fail "homing did not finish"; }
vm_wait 10 logged "native CAN node 3 on $iface" dev3.out || { cat dev3.out; vm_fail "not serving after homing"; }
[ "$(value 1)" = 0 ] || vm_fail "enable high after homing (idle)"
pull 3 pull-up  # the armed switch closes again
vm_wait 10 logged "FAULT at tick .*: limit switch x- (axis 0, negative side)" dev3.out ||
  { cat dev3.out; vm_fail "the re-armed x- switch did not fault"; }
kill -INT "$dev"
wait "$dev" || { cat dev3.out; vm_fail "the device failed"; }
cat dev3.out
released

# 4. Homing and the pen as bus commands: `ctl home` while the device serves, the switch played
#    from the device's log as in 3; then `ctl pen down` lowers the real pen line at rest.
timeout -s KILL 60 pathstream device -m "$profile" --can "$iface" --node 3 > dev4.out 2>&1 &
dev=$!
vm_wait 10 rx_ready 1 || { cat dev4.out; vm_fail "the device did not open $iface"; }
target="can://$iface?node=3&protocol=native"
timeout -s KILL 60 pathstream ctl "$target" home -m "$profile" > ctl4.out 2>&1 &
ctl=$!
vm_wait 10 logged "x: searching" dev4.out || { cat dev4.out ctl4.out; vm_fail "ctl home did not start homing"; }
vm_wait 5 line_is 1 1 || vm_fail "enable not high while homing over the bus"
usleep 300000
pull 3 pull-up
vm_wait 10 logged "x: backing off" dev4.out || { cat dev4.out; vm_fail "no back-off (ctl home)"; }
pull 3 pull-down
vm_wait 10 logged "x: approaching slowly" dev4.out || { cat dev4.out; vm_fail "no slow approach (ctl home)"; }
usleep 300000
pull 3 pull-up
vm_wait 10 logged "x: pulling off the switch" dev4.out || { cat dev4.out; vm_fail "no pull-off (ctl home)"; }
pull 3 pull-down
wait "$ctl"
rc=$?
cat ctl4.out
[ "$rc" = 0 ] || { cat dev4.out; vm_fail "ctl home exited $rc"; }
logged "homing        x homed" ctl4.out || vm_fail "ctl home did not report x homed"
logged "x: homed: switch point = 0.000 mm" dev4.out || { cat dev4.out; vm_fail "the device did not log x homed"; }
[ "$(value 0)" = 0 ] || vm_fail "pen down before ctl pen down"
pathstream ctl "$target" pen down > ctl5.out 2>&1 || { cat ctl5.out; vm_fail "ctl pen down failed"; }
vm_wait 5 line_is 0 1 || vm_fail "ctl pen down did not lower the pen line"
[ "$(value 1)" = 0 ] || vm_fail "enable high with only the pen down (idle)"
pathstream ctl "$target" pen up > ctl5.out 2>&1 || { cat ctl5.out; vm_fail "ctl pen up failed"; }
vm_wait 5 line_is 0 0 || vm_fail "ctl pen up did not raise the pen line"
kill -INT "$dev"
wait "$dev" || { cat dev4.out; vm_fail "the device failed"; }
cat dev4.out
released
vm_log "gpio cli: stream + e-stop, homing error, homing + armed switch through pathstream device --machine, ctl home and pen over CAN"
