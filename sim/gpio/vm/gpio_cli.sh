# `pathstream device --machine` on a real kernel's gpio-sim (runs inside the VM; helpers from
# sim/vm/vm_lib.sh; docs/gpio.md). The CLI opens the profile's lines through libgpiod:
#   line 0 pen (out), 1 enable (out), 2 estop (in), 3 limit-x = x- (in), 4 limit-y = y+ (in,
#   active low). The e-stop is pressed through the sim's pull attribute; the limit switch x- is
#   played by the device's own simulated axis (--sim-switch), never by the script.
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

# 3. Homing with the x- switch played by the simulated axis (--sim-switch: closed at -5 mm and
#    below, 0.05 mm hysteresis, 2 bounces after every change), then serving; a jog back onto the
#    re-armed switch faults by name.
sims="--sim-switch x-=-5 --switch-hysteresis 0.05 --switch-bounce 2"
timeout -s KILL 60 pathstream device -m "$profile" --home --can "$iface" --node 3 $sims > dev3.out 2>&1 &
dev=$!
vm_wait 10 logged "x: searching" dev3.out || { cat dev3.out; vm_fail "homing did not start"; }
vm_wait 5 line_is 1 1 || vm_fail "enable not high while homing"
vm_wait 30 logged "native CAN node 3 on $iface" dev3.out || { cat dev3.out; vm_fail "not serving after homing"; }
for phase in "x: backing off" "x: approaching slowly" "x: pulling off the switch" \
             "x: homed: switch point = 0.000 mm"; do
  logged "$phase" dev3.out || { cat dev3.out; vm_fail "homing did not log '$phase'"; }
done
[ "$(value 1)" = 0 ] || vm_fail "enable high after homing (idle)"
[ "$(value 3)" = 0 ] || vm_fail "x- still closed 1 mm off the switch"
target="can://$iface?node=3&protocol=native"
vm_run pathstream ctl "$target" jog x -2 -m "$profile" > jog3.out 2>&1
vm_wait 10 logged "FAULT at tick .*: limit switch x- (axis 0, negative side)" dev3.out ||
  { cat dev3.out jog3.out; vm_fail "the jog onto the re-armed x- switch did not fault"; }
[ "$(value 3)" = 1 ] || vm_fail "x- not closed where the jog stopped"
kill -INT "$dev"
wait "$dev" || { cat dev3.out; vm_fail "the device failed"; }
cat dev3.out
released

# 4. Homing and the pen as bus commands: `ctl home` while the device serves, the switch played
#    by the axis as in 3; then `ctl pen down` lowers the real pen line at rest.
timeout -s KILL 60 pathstream device -m "$profile" --can "$iface" --node 3 $sims > dev4.out 2>&1 &
dev=$!
vm_wait 10 rx_ready 1 || { cat dev4.out; vm_fail "the device did not open $iface"; }
timeout -s KILL 60 pathstream ctl "$target" home -m "$profile" > ctl4.out 2>&1 &
ctl=$!
vm_wait 10 logged "x: searching" dev4.out || { cat dev4.out ctl4.out; vm_fail "ctl home did not start homing"; }
vm_wait 5 line_is 1 1 || vm_fail "enable not high while homing over the bus"
wait "$ctl"
rc=$?
cat ctl4.out
[ "$rc" = 0 ] || { cat dev4.out; vm_fail "ctl home exited $rc"; }
logged "homing        x homed" ctl4.out || vm_fail "ctl home did not report x homed"
for phase in "x: backing off" "x: approaching slowly" "x: pulling off the switch" "x: homed: switch point = 0.000 mm"; do
  logged "$phase" dev4.out || { cat dev4.out; vm_fail "ctl home: the device did not log '$phase'"; }
done
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
