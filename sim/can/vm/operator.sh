# An operator's session over native CAN on a real kernel (runs inside the VM; helpers from
# sim/vm/vm_lib.sh): `pathstream device --can vcan0 --node 5` in the background, then
# `pathstream ctl` status, jog and set position, a stream interrupted by SIGINT (the device
# holds at rest, exit 7) and continued with `stream --resume`, and a stream with the lead-in that
# reads the device's rest position from status frame E.
iface=vcan0
data=/pathstream/data
target="can://$iface?node=5"
rx_ready() { [ "$(grep -c "^ *$iface " /proc/net/can/rcvlist_all)" -ge "$1" ]; }

timeout -s KILL 40 pathstream device -m "$data/pen_plotter.json" --no-gpio --can "$iface" --node 5 \
  --position 0,0 --exit-after 35 > device.out 2>&1 &
dev=$!
vm_wait 10 rx_ready 1 || vm_fail "pathstream device did not open $iface: $(cat device.out)"

vm_expect_out 0 status.json pathstream ctl "$target" status --json
grep -q '"state": "idle"' status.json || vm_fail "ctl status: not idle: $(cat status.json)"
vm_expect_out 0 jog.out pathstream ctl "$target" jog x 2.5 -m "$data/pen_plotter.json"
grep -q 'x 2.5000 mm' jog.out || vm_fail "ctl jog: $(cat jog.out)"
vm_expect_out 0 pos.out pathstream ctl "$target" position x 0 -m "$data/pen_plotter.json"
grep -q 'x 0.0000 mm' pos.out || vm_fail "ctl position: $(cat pos.out)"
vm_expect_out 6 hold.out pathstream ctl "$target" hold

# wave.json starts at 0,0: interrupt it part way, then resume from the journal.
pathstream stream "$data/wave.json" -m "$data/pen_plotter.json" -t "$target" --journal j.json > s1.out 2>&1 &
s1=$!
running() { ! kill -0 "$s1" 2>/dev/null || pathstream ctl "$target" status 2>/dev/null | grep -q '^state         running'; }
vm_wait 20 running || vm_fail "the stream never started the device: $(cat s1.out)"
sleep 0.2
kill -INT "$s1" 2>/dev/null
wait "$s1"; rc=$?
cat s1.out
if [ "$rc" = 7 ]; then
  # Held at rest (the usual case), or stopped when the device had not started yet.
  vm_expect_out 0 held.out pathstream ctl "$target" status
  if grep -q '"outcome": "held"' j.json; then
    grep -q '^state         holding' held.out || vm_fail "device not holding after the interrupt: $(cat held.out)"
  else
    grep -q '"outcome": "stopped"' j.json || vm_fail "journal after the interrupt: $(cat j.json)"
    grep -q '^state         idle' held.out || vm_fail "device not idle after the stop: $(cat held.out)"
  fi
  vm_expect_out 0 s2.out pathstream stream --resume j.json
  cat s2.out
  grep -q "^job .*finished" s2.out || vm_fail "resumed stream did not finish"
elif [ "$rc" != 0 ]; then
  vm_fail "interrupted stream exited $rc"
fi
grep -q '"outcome": "finished"' j.json || vm_fail "journal at the end: $(cat j.json)"

# The device rests at wave.json's end (60, 0): drawn in the file's direction (--keep-order; the
# order would start at the nearer end), the default lead-in goes from there to (0, 0) over CAN.
vm_expect 0 pathstream stream "$data/wave.json" -m "$data/pen_plotter.json" -t "$target" --keep-order --no-journal \
  > s3.out 2>&1 || { cat s3.out; vm_fail "the lead-in over CAN failed"; }
grep -q '^lead-in       pen up from where the device rests, x 60.0000 mm y 0.0000 mm, to the drawing.s start' s3.out ||
  vm_fail "lead-in: $(cat s3.out)"

kill -INT "$dev"
wait "$dev"
vm_log "native CAN operator session: ctl status/jog/position, interrupt and resume, lead-in: ok"
