# VM self-test, SocketCAN (runs inside the VM; helpers from sim/vm/vm_lib.sh).
# vm_selftest talks to itself over vcan0 through two raw sockets, cansend talks to vm_selftest,
# and candump (started first) must have seen every frame on the bus.
iface=vcan0
rx_ready() { grep -q "^ *$iface " /proc/net/can/rcvlist_all; }

timeout -s KILL 20 candump -L -n 4 "$iface" > candump.log &
dump=$!
vm_wait 10 rx_ready || vm_fail "candump did not open $iface"

vm_expect 0 vm_selftest can "$iface"

# cansend (can-utils) -> vm_selftest, once the receiver has bound its socket.
timeout -s KILL 20 vm_selftest can-recv "$iface" 7FF 10000 /tmp/recv.ready > recv.out &
recv=$!
vm_wait 10 test -f /tmp/recv.ready || vm_fail "vm_selftest can-recv did not start"
vm_expect 0 cansend "$iface" 7FF#0102
wait "$recv" || vm_fail "vm_selftest can-recv failed"
grep -qx '7FF#0102' recv.out || vm_fail "can-recv printed '$(cat recv.out)'"

wait "$dump" || vm_fail "candump did not capture 4 frames"
cat candump.log
for frame in 123#DEADBEEF 124#01 01ABCDEF#0001020304050607 7FF#0102; do
  grep -q " $iface $frame\$" candump.log || vm_fail "candump did not capture $frame"
done
vm_log "can: candump captured all 4 frames"
