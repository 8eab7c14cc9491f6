#!/usr/bin/env bash
# Interoperability: Debian's mbpoll (an independent libmodbus-based master) against our
# ModbusServer (pathstream_modbus_test_server: input register a = 1000 + a), over TCP on an
# ephemeral port and over RTU on a pty the server creates.
#   mbpoll_interop.sh MBPOLL SERVER_BINARY WORK_DIR
# mbpoll numbers references from 1 by default (-r 1 = PDU address 0); -0 makes them 0-based.
set -u
mbpoll=$1 server=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
failures=0 passed=0
server_pid=""
cleanup() { [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null; wait 2>/dev/null; }
trap cleanup EXIT

start_server() {  # start_server MODE ARGS... ; sets server_pid and waits for its ready line
  cleanup
  "$server" "$@" --seconds 30 > "$work/server.out" 2> "$work/server.err" &
  server_pid=$!
  for _ in $(seq 1 100); do
    [ -s "$work/server.out" ] && return 0
    sleep 0.05
  done
  echo "FAIL server did not start: $(cat "$work/server.err")"; exit 1
}

# check NAME EXPECTED_LINES -- mbpoll args: runs mbpoll, compares its "[ref]: value" lines.
check() {
  local name=$1 want=$2; shift 3
  local out got
  out=$(timeout 10 "$mbpoll" "$@" 2>&1)
  got=$(printf '%s\n' "$out" | grep -E '^\[[0-9]+\]:' | tr -d ' \t' | tr '\n' ' ')
  if [ "$got" != "$want" ]; then
    echo "FAIL $name: got '$got', want '$want'"; echo "$out" | tail -5; failures=$((failures + 1))
  else
    passed=$((passed + 1))
  fi
}

expect_text() {  # expect_text NAME NEEDLE -- mbpoll args
  local name=$1 needle=$2; shift 3
  local out
  out=$(timeout 10 "$mbpoll" "$@" 2>&1)
  if [[ "$out" != *"$needle"* ]]; then
    echo "FAIL $name: no '$needle' in:"; echo "$out" | tail -5; failures=$((failures + 1))
  else
    passed=$((passed + 1))
  fi
}

ten="[1]:1000 [2]:1001 [3]:1002 [4]:1003 [5]:1004 [6]:1005 [7]:1006 [8]:1007 [9]:1008 [10]:1009 "

start_server tcp
port=$(awk '/^port /{print $2}' "$work/server.out")
check tcp-fc4 "$ten" -- -m tcp -a 1 -r 1 -c 10 -t 3 -1 -p "$port" 127.0.0.1
check tcp-fc4-zero-based "[5]:1005 [6]:1006 " -- -m tcp -a 1 -0 -r 5 -c 2 -t 3 -1 -p "$port" 127.0.0.1
expect_text tcp-fc16 "Written 3 references" -- -m tcp -a 1 -r 11 -t 4 -1 -p "$port" 127.0.0.1 7 8 9
expect_text tcp-fc6 "Written 1 references" -- -m tcp -a 1 -r 14 -t 4 -1 -p "$port" 127.0.0.1 65535
check tcp-fc3-hex "[11]:0x0007 [12]:0x0008 [13]:0x0009 [14]:0xFFFF [15]:0x0000 " -- -m tcp -a 1 -r 11 -c 5 -t 4:hex -1 -p "$port" 127.0.0.1
expect_text tcp-exception "Illegal data address" -- -m tcp -a 1 -r 65536 -c 2 -t 3 -1 -p "$port" 127.0.0.1

start_server rtu-pty --unit 7
device=$(awk '/^device /{print $2}' "$work/server.out")
check rtu-fc4 "$ten" -- -m rtu -b 115200 -P none -a 7 -r 1 -c 10 -t 3 -1 "$device"
expect_text rtu-fc16 "Written 2 references" -- -m rtu -b 115200 -P none -a 7 -r 1 -t 4 -1 "$device" 300 301
check rtu-fc3 "[1]:300 [2]:301 [3]:0 " -- -m rtu -b 115200 -P none -a 7 -r 1 -c 3 -t 4 -1 "$device"
expect_text rtu-other-unit "timed out" -- -m rtu -b 115200 -P none -a 8 -o 0.2 -r 1 -c 1 -t 3 -1 "$device"

echo "mbpoll interop: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
