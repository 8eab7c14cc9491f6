# CiA 402 CSP end to end on a real kernel (runs inside the VM; helpers from sim/vm/vm_lib.sh):
# two `pathstream drive --can vcan0 --node 1|2` in the background, `pathstream stream ...
# --target can://vcan0?node=1&protocol=cia402&cycle=10ms` in the foreground, candump -L
# capturing the bus. A 10 ms cycle because TCG timing is not a real-time one (docs/vm.md).
# Checks: the stream completed, the capture holds NMT, SDO, SYNC, RPDO1, RPDO2 (the velocity
# feed-forward, on by default), TPDO1 and heartbeat frames of both nodes, and each drive ended
# where the plan ends, disabled.
iface=vcan0
data=/pathstream/data
rx_ready() { [ "$(grep -c "^ *$iface " /proc/net/can/rcvlist_all)" -ge "$1" ]; }

timeout -s KILL 40 candump -L "$iface" > capture.log &
dump=$!
vm_wait 10 rx_ready 1 || vm_fail "candump did not open $iface"

timeout -s KILL 40 pathstream drive --can "$iface" --node 1 --exit-after 35 > drive1.out 2>&1 &
d1=$!
timeout -s KILL 40 pathstream drive --can "$iface" --node 2 --exit-after 35 > drive2.out 2>&1 &
d2=$!
vm_wait 10 rx_ready 3 || vm_fail "pathstream drive did not open $iface: $(cat drive1.out drive2.out)"

vm_expect_out 0 stream.out pathstream stream "$data/wave.json" --machine "$data/pen_plotter.json" \
  --target "can://$iface?node=1&protocol=cia402&cycle=10ms" \
  || { cat drive1.out drive2.out; vm_fail "pathstream stream failed"; }
cat stream.out
grep -q "^executed .*motion cycles" stream.out || vm_fail "stream did not report completion"

kill -INT "$d1" "$d2"
wait "$d1"
wait "$d2"
cat drive1.out drive2.out
kill "$dump" 2>/dev/null
wait "$dump" 2>/dev/null

# candump -L lines: "(time) vcan0 ID#DATA".
for id in 000 080 181 182 201 202 301 302 581 582 601 602 701 702; do
  n=$(grep -c " $iface $id#" capture.log)
  vm_log "frames 0x$id: $n"
  [ "$n" -gt 0 ] || vm_fail "capture holds no 0x$id frame"
done

# Both drives disabled at the end (shutdown: ready to switch on), at the plan's end point.
vm_expect 0 pathstream plan "$data/wave.json" --machine "$data/pen_plotter.json" --out plan.csv > /dev/null
end_x=$(tail -n 1 plan.csv | awk -F, '{ printf "%d", $3 * 1000 + ($3 < 0 ? -0.5 : 0.5) }')
end_y=$(tail -n 1 plan.csv | awk -F, '{ printf "%d", $4 * 1000 + ($4 < 0 ? -0.5 : 0.5) }')
for n in 1 2; do
  grep -q "stopped in state ready to switch on" drive$n.out || vm_fail "drive $n did not end disabled"
done
p1=$(sed -n 's/.* at \(-*[0-9]*\) LSB;.*/\1/p' drive1.out)
p2=$(sed -n 's/.* at \(-*[0-9]*\) LSB;.*/\1/p' drive2.out)
vm_log "end point $end_x,$end_y LSB; drives at $p1,$p2"
[ $((p1 - end_x)) -le 20 ] && [ $((end_x - p1)) -le 20 ] || vm_fail "drive 1 at $p1, plan ends at $end_x"
[ $((p2 - end_y)) -le 20 ] && [ $((end_y - p2)) -le 20 ] || vm_fail "drive 2 at $p2, plan ends at $end_y"
vm_log "CiA 402 CSP stream: completed, $(wc -l < capture.log) frames captured"
