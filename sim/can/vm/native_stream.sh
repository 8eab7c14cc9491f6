# Native CAN end to end on a real kernel (runs inside the VM; helpers from sim/vm/vm_lib.sh):
# `pathstream device --can vcan0 --node 5` in the background, `pathstream stream ... --target
# can://vcan0?node=5&protocol=native` in the foreground, candump -L capturing the bus. Checks:
# the stream completed, a second drawing (wave.json backwards, which starts where the first
# ended) streams straight after it with no command in between (the first job ended idle at
# rest), the capture holds span and status frames of node 5, and the device's recorded path
# ticks equal `pathstream plan`'s setpoints of the two drawings, one after the other.
iface=vcan0
data=/pathstream/data
rx_ready() { [ "$(grep -c "^ *$iface " /proc/net/can/rcvlist_all)" -ge "$1" ]; }

timeout -s KILL 25 candump -L "$iface" > capture.log &
dump=$!
vm_wait 10 rx_ready 1 || vm_fail "candump did not open $iface"

timeout -s KILL 25 pathstream device --axes 2 --can "$iface" --node 5 --time-scale 4 \
  --record rec.csv --exit-after 20 > device.out 2>&1 &
dev=$!
vm_wait 10 rx_ready 2 || vm_fail "pathstream device did not open $iface: $(cat device.out)"

vm_expect 0 pathstream stream "$data/wave.json" --machine "$data/pen_plotter.json" \
  --target "can://$iface?node=5&protocol=native" --link-timeout 5 > stream.out 2>&1 \
  || { cat stream.out; vm_fail "pathstream stream failed"; }
cat stream.out
grep -q "^executed .*last span" stream.out || vm_fail "stream did not report completion"

# The same curve backwards: it starts exactly where the first job left the device.
cat > wave_back.json <<'JSON'
{ "units": "mm", "basis": "catmull-rom",
  "points": [[60, 0], [50, 8], [40, 0], [30, -8], [20, 0], [10, 8], [0, 0]] }
JSON
vm_expect 0 pathstream stream wave_back.json --machine "$data/pen_plotter.json" \
  --target "can://$iface?node=5&protocol=native" --link-timeout 5 > stream2.out 2>&1 \
  || { cat stream2.out; vm_fail "the second drawing was refused or failed"; }
cat stream2.out
grep -q "^executed .*last span" stream2.out || vm_fail "second stream did not report completion"

kill -INT "$dev"
wait "$dev"
cat device.out
kill "$dump" 2>/dev/null
wait "$dump" 2>/dev/null

# candump -L lines: "(time) vcan0 ID#DATA". Node 5: span start 0x405, span data 0x485,
# status A/B/C/D 0x205/0x285/0x305/0x505, acks 0x185, commands 0x105, configuration 0x385.
for id in 105 185 205 285 305 385 405 485 505; do
  n=$(grep -c " $iface $id#" capture.log)
  vm_log "frames 0x$id: $n"
  [ "$n" -gt 0 ] || vm_fail "capture holds no 0x$id frame"
done

vm_expect 0 pathstream plan "$data/wave.json" --machine "$data/pen_plotter.json" --out plan.csv > /dev/null
# The stream orders from where the device rests (60, 0): the file order; the origin would reverse it.
vm_expect 0 pathstream plan wave_back.json --machine "$data/pen_plotter.json" --keep-order --out plan2.csv > /dev/null
# plan*.csv: tick,t,x,y,pen in mm (0.001 mm per LSB), ticks 0..N (N: the end point after the
# last tick); rec.csv: tick,x,y,pen in LSB, the executed path ticks of both jobs. The second
# plan's ticks follow the first's N1 (its tick 0 is the first's end point, the same point).
awk -F, 'FILENAME == ARGV[1] { if (FNR > 1) { px[$1] = $3; py[$1] = $4; n1 = $1 } next }
         FILENAME == ARGV[2] { if (FNR > 1) { px[$1 + n1] = $3; py[$1 + n1] = $4; n = $1 + n1 + 1 } next }
         FNR > 1 { k = $1; m++
                   if (sprintf("%.3f", $2 / 1000) != sprintf("%.3f", px[k]) ||
                       sprintf("%.3f", $3 / 1000) != sprintf("%.3f", py[k])) { bad++; if (bad < 5) print "tick " k ": " $2 "," $3 " vs " px[k] "," py[k] } }
         END { print m " recorded ticks, " n " planned, " bad + 0 " differ"; exit (m > 0 && m + 1 == n && bad == 0) ? 0 : 1 }' \
  plan.csv plan2.csv rec.csv || vm_fail "the device's path ticks differ from pathstream plan's setpoints"
vm_log "native CAN stream: two drawings in a row completed, $(wc -l < capture.log) frames captured, setpoints identical"
